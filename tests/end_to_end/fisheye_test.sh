#!/bin/bash
# Fisheye end to end: the in-repository sample (fountain-P11-small, 1024x683, known K)
# warped through a known OPENCV_FISHEYE camera (tessera_test_fisheye) reconstructs with
# all 11 images registered in one model, with camera.model OPENCV_FISHEYE and the
# calibration as camera.params; `colmap model_analyzer` reads the OPENCV_FISHEYE model
# Tessera wrote (skipped without colmap, a failure under CI=true); the gaussian_splatting
# export, undistorted to PINHOLE, loads as a 3DGS scene, and so does its export with
# field_of_view "full" (a mask per image); a bad parameter count is exit 2 naming
# camera.params.
# usage: fisheye_test.sh TESSERA WARP SOURCE_DIR
set -uo pipefail
tessera=$1
warp=$2
source_dir=$3
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sample="$source_dir/examples/fountain-P11-small"
params="1050 1050 512 341.5 0.05 -0.02 0.0 0.0"
"$warp" "$sample/images" "$sample/K.txt" "$work/images" $params > /dev/null || fail "warp"
cat > "$work/m.json" <<JSON
{"pipeline": {"detector": {"plugin": "sift", "options": {"max_num_features": 4000}},
              "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "flann", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": [{"plugin": "colmap_binary"}, {"plugin": "gaussian_splatting"}]},
 "camera": {"model": "OPENCV_FISHEYE", "params": [${params// /, }]}}
JSON
"$tessera" run --images "$work/images" --output "$work/out" --manifest "$work/m.json" \
  --threads 2 > "$work/run.log" 2>&1 || { tail -30 "$work/run.log"; fail "tessera run"; }
python3 - "$work/out/mapping_summary.json" <<'PY' || fail "not all 11 in one model"
import json, sys
models = json.load(open(sys.argv[1]))["models"]
assert len(models) == 1 and models[0]["num_images"] == 11, [m["num_images"] for m in models]
PY
grep -q "OPENCV_FISHEYE" "$work/run.log" || fail "the camera is not OPENCV_FISHEYE"
echo "fisheye sample: 11 of 11 registered in one model"
python3 "$source_dir/tests/tools/check_3dgs_scene.py" "$work/out/gaussian_splatting" 11 ||
  fail "the undistorted PINHOLE workspace does not load as a 3DGS scene"
"$tessera" export --model "$work/out/sparse/0" --format gaussian_splatting --output "$work/out" \
  --images "$work/images" --options '{"folder": "full_field", "field_of_view": "full"}' \
  > "$work/full.log" 2>&1 || { cat "$work/full.log"; fail "export with field_of_view full"; }
python3 "$source_dir/tests/tools/check_3dgs_scene.py" "$work/out/full_field" 11 ||
  fail "the full-field PINHOLE workspace does not load as a 3DGS scene"
[ "$(ls "$work/out/full_field/masks" | wc -l)" = 11 ] || fail "full field: not one mask per image"
echo "full field of view: loads as a 3DGS scene, a mask per image"
if have_colmap; then
  colmap model_analyzer --path "$work/out/sparse/0" > "$work/analyzer.log" 2>&1 ||
    { cat "$work/analyzer.log"; fail "colmap model_analyzer cannot read the OPENCV_FISHEYE model"; }
  grep -q "Registered images: 11" "$work/analyzer.log" ||
    { cat "$work/analyzer.log"; fail "colmap model_analyzer: not 11 registered images"; }
  echo "colmap model_analyzer reads the OPENCV_FISHEYE model: 11 registered images"
else
  skip_part_or_fail "colmap is not installed: the model_analyzer check did not run"
fi
sed 's/"params": \[[^]]*\]/"params": [1050, 1050, 512, 341.5]/' "$work/m.json" > "$work/bad.json"
"$tessera" run --images "$work/images" --output "$work/bad" --manifest "$work/bad.json" > "$work/bad.log" 2>&1
code=$?
[ "$code" = 2 ] || fail "bad camera.params: exit $code, expected 2"
grep -q "camera.params: OPENCV_FISHEYE takes 8 parameters" "$work/bad.log" || { cat "$work/bad.log"; fail "bad camera.params: message"; }
echo "PASS: a bad camera.params count is exit 2 naming camera.params"
