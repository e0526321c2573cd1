#!/bin/bash
# `tessera triangulate` (issue 58): points for known poses, every pose held.
#  1. fountain-P11 at 1024 px: extract and match, then triangulate from the Strecha ground
#     truth (gt/*.camera, K scaled to the copy) written as a COLMAP text model: every pose
#     is the input's to 1e-12, the mean reprojection error is under 1 px, and there are
#     thousands of points; --json says the same.
#  2. lego-100: the 20 views nearest view 0, at 400 px, triangulated from transforms.json
#     (intrinsics scaled to the copy): the centres and rotations are the file's, the error
#     under 1 px; the 80 frames the workspace lacks are named in one warning.
#  3. Bad input, each exit 2 with one line naming the file and the image or field: no image
#     in common, a pose that is not a rotation, NaN in transforms.json, a model with no
#     cameras, a camera size that is not the workspace's images', neither --model nor
#     --poses.
# usage: triangulate_test.sh TESSERA DOWNSCALE SHARED_DIR
set -uo pipefail
tessera=$1
downscale=$2
shared=${TESSERA_SHARED_DIR:-$3}
source "$(dirname "$0")/common.sh"
fountain="$shared/datasets/fountain-P11"
lego="$shared/datasets/lego-100"
require_dataset "$fountain"
require_dataset "$lego"
[ -d "$fountain/gt" ] || skip_or_fail "$fountain/gt not found"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cat > "$work/m.json" << 'JSON'
{"pipeline": {"detector": {"plugin": "sift", "options": {"max_num_features": 4000}},
              "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "flann", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": [{"plugin": "colmap_binary"}]},
 "camera": {"model": "PINHOLE", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15}}
JSON
prepare() {  # prepare IMAGES WS: extract and match
  for verb in extract match; do
    "$tessera" "$verb" --images "$1" --output "$2" --manifest "$work/m.json" --threads 2 \
      > "$work/$verb.log" 2>&1 || { tail -20 "$work/$verb.log"; fail "$verb $1"; }
  done
}
# check_model KNOWN_POSES.json SPARSE MAX_ROTATION_ERROR: every image of SPARSE (binary) has
# the pose of the file (name: [qw, qx, qy, qz, tx, ty, tz] or name: {R, C}) to 1e-12 (the
# rotation to MAX_ROTATION_ERROR where the file's matrices are not quite rotations); prints
# "images points mean_error".
check_model() {
  python3 - "$@" << 'PY'
import json, math, struct, sys
known = json.load(open(sys.argv[1]))
sparse, max_rotation_error = sys.argv[2], float(sys.argv[3])
def quat_to_matrix(w, x, y, z):
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]
data = open(sparse + "/images.bin", "rb").read()
count, = struct.unpack_from("<Q", data, 0)
offset = 8
seen = 0
for _ in range(count):
    image_id, qw, qx, qy, qz, tx, ty, tz, camera_id = struct.unpack_from("<i7di", data, offset)
    offset += 64
    end = data.index(b"\0", offset)
    name = data[offset:end].decode()
    offset = end + 1
    n, = struct.unpack_from("<Q", data, offset)
    offset += 8 + n * 24
    pose = known[name]
    R = quat_to_matrix(qw, qx, qy, qz)
    if isinstance(pose, list):
        error = max(abs(a - b) for a, b in zip([qw, qx, qy, qz, tx, ty, tz], pose))
        if error > 1e-12:
            sys.exit(f"{name}: pose {[qw, qx, qy, qz, tx, ty, tz]} is not the input's {pose}")
    else:
        center = [-sum(R[k][i] * [tx, ty, tz][k] for k in range(3)) for i in range(3)]
        error = max(abs(a - b) for a, b in zip(center, pose["C"]))
        if error > 1e-12:
            sys.exit(f"{name}: centre {center} is not the input's {pose['C']} ({error})")
        error = max(abs(R[i][j] - pose["R"][i][j]) for i in range(3) for j in range(3))
        if error > max_rotation_error:
            sys.exit(f"{name}: rotation {R} is not the input's {pose['R']} ({error})")
    seen += 1
if seen != len(known):
    sys.exit(f"{seen} images in {sparse}, {len(known)} expected")
data = open(sparse + "/points3D.bin", "rb").read()
count, = struct.unpack_from("<Q", data, 0)
offset, errors = 8, []
for _ in range(count):
    error, = struct.unpack_from("<d", data, offset + 35)
    n, = struct.unpack_from("<Q", data, offset + 43)
    errors.append(error)
    offset += 51 + n * 8
print(seen, count, sum(errors) / max(1, len(errors)))
PY
}
expect_refused() {  # expect_refused NAME PATTERN ARGS...: exit 2, one line matching PATTERN
  local name=$1 pattern=$2
  shift 2
  "$tessera" triangulate "$@" > "$work/$name.log" 2>&1
  local code=$?
  [ "$code" = 2 ] || { cat "$work/$name.log"; fail "$name: exit $code, not 2"; }
  grep -qE -- "$pattern" "$work/$name.log" ||
    { cat "$work/$name.log"; fail "$name: no line matching '$pattern'"; }
  echo "refused as expected ($name): $(grep -E -- "$pattern" "$work/$name.log" | head -1)"
}

# 1. fountain-P11 from its Strecha cameras.
scale=$("$downscale" "$fountain/images" "$work/fountain" 1024 95) || fail "downscale"
prepare "$work/fountain" "$work/ws"
# gt/*.camera as a COLMAP text model of the copy ($work/gt), with the poses as written
# ($work/gt.json), and the same with the full-size K ($work/gt_full) for a size mismatch.
python3 - "$fountain/gt" "$scale" "$work" << 'PY' || fail "writing the model of gt/*.camera"
import json, math, os, sys
gt, scale, work = sys.argv[1], float(sys.argv[2]), sys.argv[3]
def quaternion(R):  # of a rotation matrix, w >= 0
    w = math.sqrt(max(0.0, 1 + R[0][0] + R[1][1] + R[2][2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1 + R[0][0] - R[1][1] - R[2][2])) / 2, R[2][1] - R[1][2])
    y = math.copysign(math.sqrt(max(0.0, 1 - R[0][0] + R[1][1] - R[2][2])) / 2, R[0][2] - R[2][0])
    z = math.copysign(math.sqrt(max(0.0, 1 - R[0][0] - R[1][1] + R[2][2])) / 2, R[1][0] - R[0][1])
    n = math.sqrt(w * w + x * x + y * y + z * z)
    return [w / n, x / n, y / n, z / n]
for folder, s in (("gt", scale), ("gt_full", 1.0)):
    os.makedirs(f"{work}/{folder}")
    cameras, images, poses = [], [], {}
    for i, file in enumerate(sorted(f for f in os.listdir(gt) if f.endswith(".camera"))):
        v = [float(t) for t in open(f"{gt}/{file}").read().split()]
        K, Rwc, C, (W, H) = v[0:9], v[12:21], v[21:24], v[24:26]
        w, h = round(W * s), round(H * s)
        fx, fy = K[0] * s, K[4] * s
        cx, cy = (K[2] + 0.5) * s - 0.5, (K[5] + 0.5) * s - 0.5
        cameras.append(f"{i + 1} PINHOLE {w} {h} {fx!r} {fy!r} {cx!r} {cy!r}")
        R = [[Rwc[3 * c + r] for c in range(3)] for r in range(3)]  # cam_from_world = Rwc^T
        q = quaternion(R)
        Rq = [[1 - 2 * (q[2] ** 2 + q[3] ** 2), 2 * (q[1] * q[2] - q[0] * q[3]), 2 * (q[1] * q[3] + q[0] * q[2])],
              [2 * (q[1] * q[2] + q[0] * q[3]), 1 - 2 * (q[1] ** 2 + q[3] ** 2), 2 * (q[2] * q[3] - q[0] * q[1])],
              [2 * (q[1] * q[3] - q[0] * q[2]), 2 * (q[2] * q[3] + q[0] * q[1]), 1 - 2 * (q[1] ** 2 + q[2] ** 2)]]
        t = [-sum(Rq[r][k] * C[k] for k in range(3)) for r in range(3)]
        name = file[: -len(".camera")]
        images.append(f"{i + 1} {' '.join(repr(x) for x in q + t)} {i + 1} {name}\n\n")
        poses[name] = q + t
    open(f"{work}/{folder}/cameras.txt", "w").write("\n".join(cameras) + "\n")
    open(f"{work}/{folder}/images.txt", "w").write("".join(images))
    open(f"{work}/{folder}/points3D.txt", "w").write("")
json.dump(poses, open(f"{work}/gt.json", "w"))
PY
"$tessera" triangulate --output "$work/ws" --model "$work/gt" --json > "$work/fountain.json" \
  2> "$work/fountain.log" || { cat "$work/fountain.log"; fail "triangulate --model gt"; }
read -r images points error < <(check_model "$work/gt.json" "$work/ws/sparse/0" 0) ||
  fail "fountain-P11: the model's poses"
echo "fountain-P11 (1024 px, Strecha cameras): $images images, $points points, mean reprojection error $error px"
python3 - "$work/fountain.json" "$points" "$error" << 'PY' || fail "fountain-P11: --json"
import json, sys
summary = json.load(open(sys.argv[1]))
print("--json:", json.dumps(summary))
assert summary["images_in_common"] == 11, summary
assert summary["num_points3D"] == int(sys.argv[2]), summary
assert summary["only_in_source"] == [] and summary["only_in_workspace"] == [], summary
assert summary["mean_reprojection_error"] < 1.0, summary
assert abs(summary["mean_reprojection_error"] - float(sys.argv[3])) < 1e-6, summary
PY
[ "$images" = 11 ] || fail "fountain-P11: $images images, not 11"
[ "$points" -ge 3000 ] || fail "fountain-P11: only $points points"
python3 -c "import sys; sys.exit(not float('$error') < 1.0)" ||
  fail "fountain-P11: mean reprojection error $error px, not under 1"
if grep -q "one side only" "$work/fountain.log"; then fail "a warning of images on one side"; fi
# --refine-intrinsics: the poses still the input's, bit for bit.
"$tessera" triangulate --output "$work/ws" --model "$work/gt" --model-index 1 \
  --refine-intrinsics --manifest "$work/m.json" > "$work/refine.log" 2>&1 ||
  { cat "$work/refine.log"; fail "triangulate --refine-intrinsics"; }
read -r images points error < <(check_model "$work/gt.json" "$work/ws/sparse/1" 0) ||
  fail "fountain-P11 --refine-intrinsics: the model's poses"
echo "fountain-P11 --refine-intrinsics: $images images, $points points, mean reprojection error $error px"
[ -d "$work/ws/sparse/0" ] || fail "--model-index 1 removed sparse/0"

# 2. lego-100 from transforms.json: the 20 views nearest view 0, at 400 px.
mkdir -p "$work/lego_subset"
python3 - "$lego" "$work" << 'PY' || fail "the lego subset"
import json, math, shutil, sys
lego, work = sys.argv[1], sys.argv[2]
transforms = json.load(open(f"{lego}/transforms.json"))
frames = transforms["frames"]
centre = lambda f: [f["transform_matrix"][r][3] for r in range(3)]
nearest = sorted(frames, key=lambda f: math.dist(centre(f), centre(frames[0])))[:20]
for f in nearest:
    shutil.copy(f"{lego}/{f['file_path']}", f"{work}/lego_subset/")
json.dump({f["file_path"].split("/")[-1]: {"R": [[f["transform_matrix"][r][c] * (1 if c == 0 else -1)
                                                   for r in range(3)] for c in range(3)],
                                             "C": centre(f)} for f in nearest},
          open(f"{work}/lego.json", "w"))
PY
lego_scale=$("$downscale" "$work/lego_subset" "$work/lego" 400 95) || fail "downscale lego"
prepare "$work/lego" "$work/lego_ws"
# Every frame, intrinsics scaled to the copy: the frames the workspace lacks are warned of.
python3 - "$lego/transforms.json" "$lego_scale" "$work/transforms.json" << 'PY' ||
import json, sys
transforms = json.load(open(sys.argv[1]))
s = float(sys.argv[2])
for key in ("fl_x", "fl_y"):
    transforms[key] *= s
for key in ("cx", "cy"):
    transforms[key] = (transforms[key] + 0.5) * s - 0.5
transforms["w"], transforms["h"] = round(transforms["w"] * s), round(transforms["h"] * s)
del transforms["camera_angle_x"]
json.dump(transforms, open(sys.argv[3], "w"), indent=1)
PY
  fail "scaling transforms.json"
"$tessera" triangulate --output "$work/lego_ws" --poses "$work/transforms.json" --json \
  > "$work/lego_summary.json" 2> "$work/lego.log" ||
  { cat "$work/lego.log"; fail "triangulate --poses transforms.json"; }
# The file's rotations are float32 matrices, orthonormal to about 1e-7.
read -r images points error < <(check_model "$work/lego.json" "$work/lego_ws/sparse/0" 1e-6) ||
  fail "lego-100: the model's poses"
echo "lego-100 (20 views, 400 px, transforms.json): $images images, $points points, mean reprojection error $error px"
[ "$images" = 20 ] || fail "lego-100: $images images, not 20"
[ "$points" -ge 500 ] || fail "lego-100: only $points points"
python3 -c "import sys; sys.exit(not float('$error') < 1.0)" ||
  fail "lego-100: mean reprojection error $error px, not under 1"
[ "$(grep -c "one side only" "$work/lego.log")" = 1 ] || { cat "$work/lego.log"; fail "lego: no single warning"; }
grep -q "80 of $work/transforms.json are not in the workspace (images/r_.*and 75 more)" "$work/lego.log" ||
  { cat "$work/lego.log"; fail "lego: the warning does not name the 80 frames"; }

# 3. Bad input.
python3 - "$work" << 'PY' || fail "writing the bad inputs"
import json, os, shutil, sys
work = sys.argv[1]
transforms = json.load(open(f"{work}/transforms.json"))
other = dict(transforms, frames=[dict(f, file_path=f"elsewhere/x_{i}.png")
                                 for i, f in enumerate(transforms["frames"][:3])])
json.dump(other, open(f"{work}/none_in_common.json", "w"))
nan = json.loads(json.dumps(transforms))
nan["frames"][2]["transform_matrix"][1][3] = float("nan")
json.dump(nan, open(f"{work}/nan.json", "w"))  # Python writes NaN, which is no JSON
nan_focal = dict(transforms, frames=transforms["frames"][:2])
open(f"{work}/nan_focal.json", "w").write(json.dumps(nan_focal).replace(
    f'"fl_y": {json.dumps(transforms["fl_y"])}', '"fl_y": "NaN"'))
not_rotation = json.loads(json.dumps(transforms))
not_rotation["frames"][1]["transform_matrix"][0][0] *= 2
json.dump(not_rotation, open(f"{work}/not_rotation.json", "w"))
lines = open(f"{work}/gt/images.txt").read().splitlines(True)
for folder, qvec in (("zero_quaternion", "0 0 0 0"), ("nan_model", "nan 0 0 0")):
    shutil.copytree(f"{work}/gt", f"{work}/{folder}")
    fields = lines[6].split()  # image 4, 0003.jpg
    fields[1:5] = qvec.split()
    changed = lines[:6] + [" ".join(fields) + "\n"] + lines[7:]
    open(f"{work}/{folder}/images.txt", "w").write("".join(changed))
os.makedirs(f"{work}/no_cameras")
for name in ("cameras.txt", "images.txt", "points3D.txt"):
    open(f"{work}/no_cameras/{name}", "w").write("# empty\n")
PY
expect_refused none_in_common "none_in_common.json: none of its 3 images \(elsewhere/x_0.png, .*\) is in the workspace" \
  --output "$work/lego_ws" --poses "$work/none_in_common.json"
expect_refused not_rotation "not_rotation.json: frames\[1\] \(images/r_1.png\): the rotation is not a rotation matrix" \
  --output "$work/lego_ws" --poses "$work/not_rotation.json"
expect_refused zero_quaternion "zero_quaternion/images.txt.*: the rotation of image 4 has length 0" \
  --output "$work/ws" --model "$work/zero_quaternion"
expect_refused nan_model "nan_model/images.txt line 7: 'nan' is not a finite quaternion component" \
  --output "$work/ws" --model "$work/nan_model"
expect_refused nan "nan.json is not valid JSON" --output "$work/lego_ws" --poses "$work/nan.json"
expect_refused nan_focal "nan_focal.json: frames\[0\] \(images/r_[0-9]+.png\): \"fl_y\" is \"NaN\", not a finite number" \
  --output "$work/lego_ws" --poses "$work/nan_focal.json"
expect_refused no_cameras "no_cameras/cameras.txt: the model has no cameras" \
  --output "$work/ws" --model "$work/no_cameras"
expect_refused size "gt_full/images.txt: image 1 \(0000.jpg\): its camera 1 is 3072x2048, but the workspace's image 0000.jpg is 1024x683" \
  --output "$work/ws" --model "$work/gt_full"
expect_refused neither "--model or --poses" --output "$work/ws"
check_model "$work/gt.json" "$work/ws/sparse/0" 0 > /dev/null || fail "a refused call changed sparse/0"
echo "PASS"
