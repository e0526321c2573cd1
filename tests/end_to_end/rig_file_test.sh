#!/bin/bash
# Rig files that cannot be used (`--rig rig.json`) end the run with exit code 2 and one
# line naming the file and the JSON field. On a 512 px copy of images of the sample
# examples/fountain-P11-small (in the repository), with ORB for speed:
#  1. malformed JSON, two reference cameras, a bad rotation, a translation no rig can
#     have (1e300 m, issue 47): exit 2 before an image is read (no workspace is made);
#  2. `run --rig` naming a camera folder that is not there: exit 2 before an image is
#     read; one that has no images: exit 2 from the map stage; both naming
#     cameras[1].folder;
#  3. `map --rig` on that workspace, the two cameras' folders with different image
#     counts: exit 2 naming the moment that one camera has no image of;
#  5. a given pose that the mapper does not hold (the global mapper maps the images one
#     by one): mapping_summary.json says "not applied" for the camera, never "given",
#     and a warning names the rig file and the camera (issue 47).
# usage: rig_file_test.sh TESSERA DOWNSCALE SOURCE_DIR
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/all" 512 90 > /dev/null ||
  fail "downscale"
mkdir -p "$work/images/left" "$work/images/right"
# left/0000..0002 and right/0000..0001: the moment 0002.jpg has no right image.
for i in 0 1 2; do cp "$work/all/000$i.jpg" "$work/images/left/000$i.jpg"; done
for i in 0 1; do cp "$work/all/000$((i + 3)).jpg" "$work/images/right/000$i.jpg"; done
cat > "$work/m.json" <<JSON
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 1500}},
              "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": {"plugin": "ceres"}},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15}}
JSON
# expect_exit_2 RIG_FILE TEXT VERB ARGS...: VERB with --rig RIG_FILE exits 2, and its
# last line of error names the file and says TEXT.
expect_exit_2() {
  local rig=$1 text=$2 verb=$3
  shift 3
  "$tessera" "$verb" --output "$work/out" --manifest "$work/m.json" --threads 2 --rig "$rig" \
    "$@" > "$work/log" 2>&1
  local code=$?
  [ "$code" = 2 ] || {
    tail -20 "$work/log"
    fail "$verb --rig $(basename "$rig"): exit code $code, not 2"
  }
  grep -qF -- "$rig: $text" "$work/log" || {
    tail -20 "$work/log"
    fail "$verb --rig $(basename "$rig"): no line '$rig: $text'"
  }
  echo "$verb --rig $(basename "$rig"): exit 2, $(grep -F -- "$rig: $text" "$work/log" | head -1 |
    sed 's/^\[error\] //')"
}

# 1. Bad files, found before an image is read.
echo '{"cameras": [{"folder": "left", "reference": true},' > "$work/malformed.json"
expect_exit_2 "$work/malformed.json" "not valid JSON" run --images "$work/images"
echo '{"cameras": [{"folder": "left", "reference": true}, {"folder": "right", "reference": true}]}' \
  > "$work/two_references.json"
expect_exit_2 "$work/two_references.json" \
  'cameras: exactly one camera must be "reference": true (2 are)' run --images "$work/images"
cat > "$work/bad_rotation.json" <<'JSON'
{"cameras": [{"folder": "left", "reference": true},
             {"folder": "right", "cam_from_rig": {"rotation_wxyz": [1, 0, 0],
                                                  "translation": [0.2, 0, 0]}}]}
JSON
expect_exit_2 "$work/bad_rotation.json" \
  "cameras[1].cam_from_rig.rotation_wxyz: must be an array of 4 numbers" run --images "$work/images"
cat > "$work/far.json" <<'JSON'
{"cameras": [{"folder": "left", "reference": true},
             {"folder": "right", "cam_from_rig": {"rotation_wxyz": [1, 0, 0, 0],
                                                  "translation": [1e300, 0, 0]}}]}
JSON
expect_exit_2 "$work/far.json" \
  "cameras[1].cam_from_rig.translation: 1e+300 m from the reference camera is beyond what a rig can be (at most 100 m) (camera 'right')" \
  run --images "$work/images"
[ ! -e "$work/out/database.db" ] || fail "a bad rig file: the workspace was made all the same"

# 2. A camera folder that is not there (before an image is read), then one with no images.
echo '{"cameras": [{"folder": "left", "reference": true}, {"folder": "center"}]}' \
  > "$work/no_images.json"
expect_exit_2 "$work/no_images.json" "cameras[1].folder: 'center' is not a folder of" \
  run --images "$work/images"
[ ! -e "$work/out/database.db" ] || fail "a rig folder that is not there: the workspace was made"
mkdir "$work/images/center"
expect_exit_2 "$work/no_images.json" "cameras[1].folder: 'center' has no images" \
  run --images "$work/images"

# 3. Inconsistent image counts, by `map` on the workspace that run made.
echo '{"cameras": [{"folder": "left", "reference": true}, {"folder": "right"}], "frames": "same_name"}' \
  > "$work/stereo.json"
expect_exit_2 "$work/stereo.json" "frames: moment '0002.jpg' has no image in 'right'" map

# 4. Partitioned mapping does not hold rigs: refused before anything is mapped.
"$tessera" map --output "$work/out" --manifest "$work/m.json" --rig "$work/stereo.json" \
  --hierarchical > "$work/log" 2>&1
code=$?
[ "$code" = 2 ] || { tail -5 "$work/log"; fail "map --rig --hierarchical: exit code $code, not 2"; }
grep -qF -- "--rig: partitioned mapping (--cluster, --cluster-shard, --hierarchical) does not hold rigs yet" \
  "$work/log" || { tail -5 "$work/log"; fail "map --rig --hierarchical: not refused as expected"; }
echo "map --rig --hierarchical: exit 2, refused"

# 5. A given pose the mapper does not hold is "not applied", with a warning.
cp "$work/all/0005.jpg" "$work/images/right/0002.jpg"
cat > "$work/given.json" <<'JSON'
{"cameras": [{"folder": "left", "reference": true},
             {"folder": "right", "cam_from_rig": {"rotation_wxyz": [1, 0, 0, 0],
                                                  "translation": [-0.5, 0, 0]}}]}
JSON
python3 - "$work/m.json" "$work/global.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["pipeline"]["mapper"] = {"plugin": "global"}
json.dump(m, open(sys.argv[2], "w"))
PY
rm -rf "$work/out"
"$tessera" run --images "$work/images" --output "$work/out" --manifest "$work/global.json" \
  --threads 2 --rig "$work/given.json" > "$work/log" 2>&1
code=$?
[ "$code" = 0 ] || { tail -20 "$work/log"; fail "run --rig with the global mapper: exit $code"; }
grep -qF "$work/given.json: cameras[1] ('right', camera " "$work/log" &&
  grep -qF "the given cam_from_rig was not applied by mapper 'global'" "$work/log" ||
  { grep -i rig "$work/log"; fail "run --rig with the global mapper: no warning that the pose was not applied"; }
python3 - "$work/out/mapping_summary.json" <<'PY' || fail "mapping_summary.json: the rig's pose not reported as not applied"
import json, sys
rig = json.load(open(sys.argv[1]))["rig"]
right = [c for c in rig["cameras"] if c["folder"] == "right"][0]
assert right["cam_from_rig"] == "not applied", rig
PY
echo "run --rig, global mapper: the given pose reported 'not applied', with a warning"
