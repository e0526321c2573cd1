#!/bin/bash
# Hand-offs read the way their readers read them (issue 47), not through Tessera's own
# reader. On a 512 px copy of the in-repository sample (5 images):
#  1. transforms.json: every file_path joined to the JSON's folder as nerfstudio and
#     instant-ngp join it (os.path.join(dirname(transforms.json), file_path)) names the
#     frame's image, byte for byte: from a run whose manifest carries the exporter (paths
#     absolute, and relative) and from `tessera export` with --images and --output
#     relative, absolute, inside each other and through "..". Without --images: exit 2
#     naming the missing file, unless the images are in images/ beside the JSON.
#  2. The 3DGS workspace loads as the reference trainer loads it, and the trainer's
#     camera (principal point at the image centre) projects every point within 0.5 px of
#     the model's camera (tests/tools/check_3dgs_scene.py): from the gaussian_splatting
#     recipe, and exported from a model whose principal point was refined off the centre.
#  3. "Mean reprojection error": mapping_summary.json's mean_reprojection_error, the map
#     log and `tessera eval` give `colmap model_analyzer`'s figure (each point's mean error
#     over its track, averaged over points) within print precision.
# usage: exits_test.sh TESSERA DOWNSCALE SOURCE_DIR
set -uo pipefail
tessera=$(realpath "$1")
downscale=$2
source_dir=$(realpath "$3")
source "$(dirname "$0")/common.sh"
check_3dgs="$source_dir/tests/tools/check_3dgs_scene.py"
have_colmap || skip_or_fail "colmap not found (scripts/install_dependencies.sh installs it)"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
proj="$work/proj"
mkdir -p "$proj/sub"
"$downscale" "$source_dir/examples/fountain-P11-small/images" "$proj/photos" 512 90 > /dev/null ||
  fail "downscale"
photos="$proj/photos"

# MANIFEST OUT REFINE: the gaussian_splatting recipe with transforms_json added, the
# principal point refined (true) or as the recipe has it (recipe).
manifest() {
  python3 - "$source_dir/manifests/gaussian_splatting.json" "$1" "$2" << 'PY'
import json, sys
manifest = json.load(open(sys.argv[1]))
manifest["pipeline"]["exporters"].append({"plugin": "transforms_json"})
if sys.argv[3] == "true":
    manifest["pipeline"]["mapper"]["options"]["ba_refine_principal_point"] = True
json.dump(manifest, open(sys.argv[2], "w"))
PY
}
manifest "$work/recipe.json" recipe
manifest "$work/refined.json" true

# resolves JSON...: each frame's file_path joined to the JSON's folder, from another
# working folder, is a file equal to the image of that name in $photos.
resolves() {
  (cd / && python3 - "$photos" "$@") << 'PY'
import filecmp, json, os, sys
photos = sys.argv[1]
for path in sys.argv[2:]:
    frames = json.load(open(path))["frames"]
    if not frames:
        sys.exit(f"FAIL: {path}: no frames")
    for frame in frames:
        resolved = os.path.join(os.path.dirname(path), frame["file_path"])
        source = os.path.join(photos, os.path.basename(frame["file_path"]))
        if not os.path.isfile(resolved):
            sys.exit(f"FAIL: {path}: file_path {frame['file_path']} resolves to {resolved}, "
                     "which does not exist")
        if not filecmp.cmp(resolved, source, shallow=False):
            sys.exit(f"FAIL: {path}: {resolved} is not {source}")
    print(f"{path}: {len(frames)} file_path resolve")
PY
}

# analyzer_matches MODEL_DIR SUMMARY LOG: model_analyzer's "Mean reprojection error"
# against mapping_summary.json (6 decimals, as colmap prints), the map log (3 decimals)
# and `tessera eval` against the model itself.
analyzer_matches() {
  local colmap_error
  colmap_error=$(colmap model_analyzer --path "$1" 2>&1 |
    sed -n 's/.*Mean reprojection error: \([0-9.]*\)px.*/\1/p')
  [ -n "$colmap_error" ] || fail "colmap model_analyzer printed no mean reprojection error for $1"
  local eval_error
  eval_error=$("$tessera" eval "$1" "$1" --json | python3 -c \
    'import json, sys; print(json.load(sys.stdin)["mean_reprojection_error_px"])') ||
    fail "tessera eval $1"
  python3 - "$colmap_error" "$2" "$3" "$eval_error" << 'PY' || fail "$1: not COLMAP's figure"
import json, re, sys
colmap = float(sys.argv[1])
model = json.load(open(sys.argv[2]))["models"][0]
ours, observations = model["mean_reprojection_error"], model["mean_observation_reprojection_error"]
logged = re.search(r"map: model 0: .* mean reprojection error ([0-9.]+) px", open(sys.argv[3]).read())
evaluated = float(sys.argv[4])
print(f"model_analyzer {colmap:.6f} px; mapping_summary.json {ours:.6f} px "
      f"(over observations {observations:.6f}); map log {logged and logged.group(1)}; "
      f"eval {evaluated:.6f}")
ok = abs(ours - colmap) <= 1e-6 and abs(evaluated - colmap) <= 1e-6
ok = ok and logged is not None and abs(float(logged.group(1)) - colmap) <= 0.0005 + 1e-6
sys.exit(0 if ok else 1)
PY
}

run() {  # run LOG ARGS...: tessera ARGS, its log in LOG
  local log=$1
  shift
  "$tessera" "$@" --threads 2 > "$log" 2>&1 || { tail -20 "$log"; fail "tessera $*"; }
}

# 1, 2, 3 from a run with absolute paths: the recipe as shipped (principal point fixed).
run "$work/a.log" run --images "$photos" --output "$proj/run" --manifest "$work/recipe.json"
resolves "$proj/run/transforms.json" || fail "run with absolute paths"
python3 "$check_3dgs" "$proj/run/gaussian_splatting" || fail "the recipe's 3DGS workspace"
analyzer_matches "$proj/run/sparse/0" "$proj/run/mapping_summary.json" "$work/a.log"

# The same with relative paths, the principal point refined (the exporter centres it).
(cd "$proj" && run "$work/b.log" run --images photos --output run2 --manifest "$work/refined.json") ||
  exit 1
resolves "$proj/run2/transforms.json" || fail "run with relative paths"
analyzer_matches "$proj/run2/sparse/0" "$proj/run2/mapping_summary.json" "$work/b.log"
python3 - "$proj/run2/sparse/0" << 'PY' || fail "the refined principal point is at the centre"
import struct, sys
f = open(sys.argv[1] + "/cameras.bin", "rb")
struct.unpack("<Q", f.read(8))
camera_id, model, width, height = struct.unpack("<iiQQ", f.read(24))
f_, cx, cy = struct.unpack("<ddd", f.read(24))
print(f"refined model: principal point ({cx - width / 2:+.2f}, {cy - height / 2:+.2f}) px "
      "off the centre")
sys.exit(0 if max(abs(cx - width / 2), abs(cy - height / 2)) > 0.5 else 1)
PY
grep -q "camera 1: principal point (.*) px off the image centre; written centred" "$work/b.log" ||
  fail "the exporter did not say it centred the principal point"
python3 "$check_3dgs" "$proj/run2/gaussian_splatting" || fail "3DGS from a refined model"

# 1. tessera export with each kind of path.
export_json() {  # export_json LOG DIR ARGS...: tessera export in DIR
  local log=$1 dir=$2
  shift 2
  (cd "$dir" && "$tessera" export --format transforms_json "$@" > "$log" 2>&1) ||
    { cat "$log"; fail "tessera export $*"; }
}
model="$proj/run/sparse/0"
export_json "$work/e1.log" "$proj" --model run/sparse/0 --output out1 --images photos
export_json "$work/e2.log" "$work" --model "$model" --output "$proj/out2" --images "$photos"
export_json "$work/e3.log" "$proj" --model run/sparse/0 --output photos/out3 --images photos
mkdir -p "$proj/out4" && cp -r "$photos" "$proj/out4/frames"
export_json "$work/e4.log" "$proj" --model "$model" --output out4 --images out4/frames
export_json "$work/e5.log" "$proj/sub" --model ../run/sparse/0 --output ../out5 --images ../photos \
  --options '{"file": "nerf/t.json"}'
export_json "$work/e6.log" "$proj/sub" --model "$model" --output "$proj/out6" --images ../photos
resolves "$proj/out1/transforms.json" "$proj/out2/transforms.json" \
  "$proj/photos/out3/transforms.json" "$proj/out4/transforms.json" "$proj/out5/nerf/t.json" \
  "$proj/out6/transforms.json" || fail "tessera export"

# Without --images: refused naming the missing image, unless images/ is beside the JSON.
(cd "$proj" && "$tessera" export --model run/sparse/0 --format transforms_json --output out7 \
  > "$work/e7.log" 2>&1)
code=$?
[ "$code" = 2 ] || { cat "$work/e7.log"; fail "export without --images: exit $code, expected 2"; }
grep -q "the image folder is unknown (tessera export --images DIR) and out7/images/.* does not exist" \
  "$work/e7.log" || { cat "$work/e7.log"; fail "export without --images: the message"; }
[ ! -e "$proj/out7/transforms.json" ] || fail "export without --images wrote transforms.json"
cp -r "$photos" "$proj/out7/images"
export_json "$work/e8.log" "$proj" --model run/sparse/0 --output out7
resolves "$proj/out7/transforms.json" || fail "export with images/ beside the JSON"
echo "PASS: transforms.json paths resolve, the 3DGS camera is centred, COLMAP's mean error"
