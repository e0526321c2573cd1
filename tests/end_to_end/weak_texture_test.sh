#!/bin/bash
# Detection that adapts to weak texture (issue 27, min_num_features). On 512 px copies of
# the sample examples/fountain-P11-small (in the repository), the original and a dark,
# low-contrast copy made here (grey v -> 0.15 v + 16), with ORB:
#  - the low-contrast copy without the option registers fewer images than the original;
#  - with min_num_features it registers as many as the original does, and the log names
#    each image whose threshold was lowered, with its counts.
# (A well-textured image is detected once, as without the option: orb_detector_test.)
# usage: weak_texture_test.sh TESSERA DOWNSCALE SOURCE_DIR
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/original" 512 95 > /dev/null ||
  fail "downscale"
"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/low" 512 95 0.15 > /dev/null ||
  fail "downscale (low contrast)"
manifest() {  # manifest FILE DETECTOR_OPTIONS
  cat > "$1" <<JSON
{"pipeline": {"detector": {"plugin": "orb", "options": $2},
              "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": [{"plugin": "colmap_binary"}]},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15}}
JSON
}
manifest "$work/plain.json" '{"max_num_features": 2000}'
manifest "$work/adaptive.json" '{"max_num_features": 2000, "min_num_features": 1500}'
# registered IMAGES MANIFEST NAME: runs, prints model 0's registered images (0: none).
registered() {
  "$tessera" run --images "$work/$1" --output "$work/$3" --manifest "$work/$2" --threads 2 \
    > "$work/$3.log" 2>&1
  local code=$?
  [ "$code" = 0 ] || [ "$code" = 3 ] || { tail -20 "$work/$3.log"; fail "run $3: exit $code"; }
  python3 -c 'import json, sys
models = json.load(open(sys.argv[1]))["models"]
print(models[0]["num_images"] if models else 0)' "$work/$3/mapping_summary.json"
}
original=$(registered original plain.json original_plain)
low_plain=$(registered low plain.json low_plain)
low_adaptive=$(registered low adaptive.json low_adaptive)
features() { sed -n 's/.* detected with \([0-9]*\) features.*, \([0-9.]*\) s$/\1 features, extraction \2 s/p' "$work/$1.log"; }
echo "original: $(features original_plain), $original registered"
echo "low contrast: $(features low_plain), $low_plain registered"
echo "low contrast, min_num_features 1500: $(features low_adaptive), $low_adaptive registered"
[ "$low_plain" -lt "$original" ] ||
  fail "the low-contrast copy registers $low_plain images without adaptation, the original $original: the copy is not weak enough to test"
[ "$low_adaptive" -ge "$original" ] ||
  fail "with min_num_features the low-contrast copy registers $low_adaptive images, the original $original"
lowered=$(grep -c "orb (image [0-9]*\.jpg): [0-9]* features at FAST threshold 20, fewer than min_num_features 1500: [0-9]* at " "$work/low_adaptive.log")
[ "$lowered" -ge 1 ] || { grep orb "$work/low_adaptive.log" | head; fail "no log line names an image whose threshold was lowered"; }
echo "the log names $lowered images whose threshold was lowered"
echo "PASS"
