#!/bin/bash
# `tessera import`: features and matches made by another program. On a 512 px copy of the
# sample examples/fountain-P11-small (11 images), OpenCV's Python API (cv2.SIFT_create,
# standing in for a learned model) writes COLMAP's feature_importer text files, then:
#  A. import with whole-number (uint8) SIFT descriptors, `match`, `map`: 11/11 registered;
#     `extract` on that workspace is refused (exit 2), and a second import changes nothing;
#  B. import the same features with a pairs file (every pair): `map` alone, 11/11;
#  C. RootSIFT float descriptors (stored as unit vectors) and raw matches from OpenCV's
#     matcher, verified by Tessera: `map`, 11/11;
#  D. the same features with the matches OpenCV's RANSAC kept, imported --verified: 11/11;
#  E. bad input: exit 2 and one line naming the file and line (mixed widths, NaN, a
#     truncated file, a keypoint index out of range, an image in no workspace).
# usage: import_test.sh TESSERA DOWNSCALE PYTHON SOURCE_DIR
set -uo pipefail
tessera=$1
downscale=$2
python=$3
source_dir=$4
source "$(dirname "$0")/common.sh"
"$python" -c "import cv2; cv2.SIFT_create" 2> /dev/null ||
  skip_or_fail "$python has no OpenCV (apt-get install python3-opencv)"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/images" 512 90 > /dev/null ||
  fail "downscale"
# The sample's K.txt is for 1024 px: halved.
printf '459.9135 0 253.5315\n0 460.916 167.963\n0 0 1\n' > "$work/K.txt"
cat > "$work/m.json" <<JSON
{"pipeline": {"detector": {"plugin": "sift"},
              "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": [{"plugin": "colmap_binary"}]},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15}}
JSON

# Features and matches by OpenCV, in COLMAP's text formats.
"$python" - "$work" <<'PY' || fail "OpenCV features"
import os, sys
import cv2
import numpy as np
work = sys.argv[1]
names = sorted(os.listdir(f"{work}/images"))
sift = cv2.SIFT_create(nfeatures=3000, contrastThreshold=0.02)
features = {}
for name in names:
    gray = cv2.imread(f"{work}/images/{name}", cv2.IMREAD_GRAYSCALE)
    keypoints, descriptors = sift.detectAndCompute(gray, None)
    # COLMAP's pixel convention: the centre of the top-left pixel is (0.5, 0.5).
    xy = np.array([k.pt for k in keypoints]) + 0.5
    frames = np.column_stack([xy, [k.size / 2 for k in keypoints],
                              [np.deg2rad(k.angle) for k in keypoints]])
    root = np.sqrt(descriptors / np.maximum(descriptors.sum(1, keepdims=True), 1e-9))
    features[name] = (frames, descriptors, root.astype(np.float32))

def write(folder, column):
    os.makedirs(folder)
    for name, f in features.items():
        with open(f"{folder}/{name}.txt", "w") as out:
            out.write(f"{len(f[0])} {f[column].shape[1]}\n")
            for frame, row in zip(f[0], f[column]):
                values = " ".join("%d" % v for v in row) if column == 1 else \
                    " ".join("%.6g" % v for v in row)
                out.write("%.3f %.3f %.3f %.4f %s\n" % (*frame, values))

write(f"{work}/sift", 1)       # whole numbers 0..255
write(f"{work}/rootsift", 2)   # floats
matcher = cv2.BFMatcher(cv2.NORM_L2, crossCheck=True)
with open(f"{work}/pairs.txt", "w") as pairs, open(f"{work}/raw.txt", "w") as raw, \
        open(f"{work}/verified.txt", "w") as verified:
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            pairs.write(f"{a} {b}\n")
            found = matcher.match(features[a][2], features[b][2])
            m = np.array([[x.queryIdx, x.trainIdx] for x in found if x.distance < 0.7])
            raw.write(f"{a} {b}\n" + "".join(f"{p} {q}\n" for p, q in m) + "\n")
            keep = m[:0]
            if len(m) >= 8:
                _, mask = cv2.findFundamentalMat(features[a][0][m[:, 0], :2],
                                                 features[b][0][m[:, 1], :2],
                                                 cv2.FM_RANSAC, 2.0, 0.999)
                if mask is not None:
                    keep = m[mask.ravel() > 0]
            verified.write(f"{a} {b}\n" + "".join(f"{p} {q}\n" for p, q in keep) + "\n")
PY

tess() {  # tess LOG ARGS...: a tessera command that must succeed
  local log=$1
  shift
  "$tessera" "$@" > "$log" 2>&1 || { tail -30 "$log"; fail "tessera $* ($log)"; }
}
registered() {  # registered WS: images in model 0
  "$python" -c 'import json, sys; print(json.load(open(sys.argv[1]))["models"][0]["num_images"])' \
    "$1/mapping_summary.json"
}
expect_registered() {  # expect_registered WS WHAT
  local n
  n=$(registered "$1")
  echo "$2: $n/11 registered"
  [ "$n" = 11 ] || fail "$2: $n of 11 images registered"
}
common=(--manifest "$work/m.json" --camera-K "$work/K.txt" --threads 2)

# A. Features, then match and map as usual.
tess "$work/a1.log" import --output "$work/A" --features "$work/sift" --images "$work/images" \
  "${common[@]}" --json
grep -q '"descriptors": "uint8"' "$work/a1.log" || { cat "$work/a1.log"; fail "A: not uint8"; }
grep -q '"num_imported": 11' "$work/a1.log" || fail "A: not 11 imported"
tess "$work/a2.log" match --output "$work/A" "${common[@]}"
tess "$work/a3.log" map --output "$work/A" "${common[@]}"
expect_registered "$work/A" "A (uint8 SIFT, match, map)"
"$tessera" extract --images "$work/images" --output "$work/A" "${common[@]}" > "$work/a4.log" 2>&1
[ $? -eq 2 ] || { cat "$work/a4.log"; fail "A: extract on imported features did not exit 2"; }
grep -q "features were imported" "$work/a4.log" || fail "A: extract's refusal does not say why"
tess "$work/a5.log" import --output "$work/A" --features "$work/sift" "${common[@]}" --json
grep -q '"num_reused": 11' "$work/a5.log" || { cat "$work/a5.log"; fail "A: a second import wrote"; }

# B. Pairs to match with the manifest's matcher, then map.
tess "$work/b1.log" import --output "$work/B" --features "$work/sift" --images "$work/images" \
  --matches "$work/pairs.txt" --match-type pairs "${common[@]}" --json
grep -q '"num_matched": 55' "$work/b1.log" || { cat "$work/b1.log"; fail "B: not 55 pairs matched"; }
tess "$work/b2.log" map --output "$work/B" "${common[@]}"
expect_registered "$work/B" "B (pairs file, map)"

# C. Float descriptors and raw matches verified by Tessera.
tess "$work/c1.log" import --output "$work/C" --features "$work/rootsift" --images "$work/images" \
  --matches "$work/raw.txt" "${common[@]}" --json
grep -q '"descriptors": "unit_float"' "$work/c1.log" || { cat "$work/c1.log"; fail "C: not float"; }
tess "$work/c2.log" map --output "$work/C" "${common[@]}"
expect_registered "$work/C" "C (float RootSIFT, raw matches, verified by Tessera)"
grep -A12 '"matches"' "$work/c1.log" | grep -E '"num_(verified|matches|inliers)"' | tr -d ' ,\n'
echo

# D. Matches verified by OpenCV, imported as verified.
tess "$work/d1.log" import --output "$work/D" --features "$work/rootsift" --images "$work/images" \
  --matches "$work/verified.txt" --verified "${common[@]}" --json
tess "$work/d2.log" map --output "$work/D" "${common[@]}"
expect_registered "$work/D" "D (float RootSIFT, raw matches --verified)"

# E. Bad input: exit 2, one line naming the file and the line.
expect_refusal() {  # expect_refusal TEXT ARGS...: exit 2 with TEXT in the output
  local text=$1
  shift
  "$tessera" import "$@" "${common[@]}" > "$work/e.log" 2>&1
  local rc=$?
  [ $rc -eq 2 ] || { cat "$work/e.log"; fail "import $*: exit $rc, not 2"; }
  grep -qF -- "$text" "$work/e.log" || { cat "$work/e.log"; fail "import $*: no '$text'"; }
}
bad=$work/bad
cp -r "$work/sift" "$bad"
awk 'NR == 1 {print $1, 64; next} {line = $1 " " $2 " " $3 " " $4; for (i = 5; i < 69; ++i) line = line " " $i; print line}' \
  "$work/sift/0003.jpg.txt" > "$bad/0003.jpg.txt"
expect_refusal "$bad/0003.jpg.txt:1: descriptors of width 64, where $bad/0000.jpg.txt:1 has width 128" \
  --output "$work/E1" --features "$bad" --images "$work/images"
cp "$work/sift/0003.jpg.txt" "$bad/0003.jpg.txt"
sed -i '5s/^[^ ]* /nan /' "$bad/0004.jpg.txt"
expect_refusal "$bad/0004.jpg.txt:5: keypoint coordinates (nan," \
  --output "$work/E2" --features "$bad" --images "$work/images"
cp "$work/sift/0004.jpg.txt" "$bad/0004.jpg.txt"
head -n 100 "$work/sift/0005.jpg.txt" > "$bad/0005.jpg.txt"
expect_refusal "$bad/0005.jpg.txt:101: truncated: the header announces" \
  --output "$work/E3" --features "$bad" --images "$work/images"
[ ! -e "$work/E3/database.db" ] || [ "$(sqlite3 "$work/E3/database.db" 'SELECT COUNT(*) FROM keypoints')" = 0 ] ||
  fail "E3: a refused import wrote keypoints"
printf '0000.jpg 0001.jpg\n0 1\n3 999999\n' > "$work/bad_raw.txt"
expect_refusal "$work/bad_raw.txt:3: keypoint index 999999 of '0001.jpg' is out of range" \
  --output "$work/A" --features "$work/sift" --matches "$work/bad_raw.txt"
printf '0000.jpg 0001.jpg\n0 1\n\n0000.jpg nowhere.jpg\n0 1\n' > "$work/bad_raw.txt"
expect_refusal "$work/bad_raw.txt:4: no image 'nowhere.jpg' in workspace" \
  --output "$work/A" --features "$work/sift" --matches "$work/bad_raw.txt"
echo "PASS"
