#!/bin/bash
# Staleness covers every input that shapes a result. On a 512 px copy of 6 images of the
# sample examples/fountain-P11-small (in the repository), with ORB for speed:
#  1. camera settings changed for a finished workspace (--camera-K; then camera.model,
#     single_camera and default_focal_length_factor in the manifest): the cameras are
#     re-created (logged, naming the settings), no image is detected again, and the model
#     is byte for byte that of a fresh workspace with the new settings;
#     `map --camera-K` applies K as extract would (a K with fx = 1e12 is refused, exit 2);
#  2. exhaustive, then `window` 2: mapping leaves out the pairs the window does not choose
#     (logged), nothing is matched again, and the model is that of a fresh workspace with
#     `window` 2; exhaustive again matches nothing again.
# Video files are keyed by content in video_test (VideoFrames.*SameSizeAndTime*).
# usage: staleness_test.sh TESSERA DOWNSCALE SOURCE_DIR
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/all" 512 90 > /dev/null ||
  fail "downscale"
mkdir -p "$work/images"
for i in 0 1 2 3 4 5; do cp "$work/all/000$i.jpg" "$work/images/"; done
# The sample's K.txt is for 1024 px: halved.
printf '459.9135 0 253.5315\n0 460.916 167.963\n0 0 1\n' > "$work/K.txt"
manifest() {  # manifest FILE CAMERA PAIR_SELECTOR
  cat > "$1" <<JSON
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 1500}},
              "pair_selector": $3,
              "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": [{"plugin": "colmap_binary"}]},
 "camera": $2,
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15}}
JSON
}
exhaustive='{"plugin": "exhaustive"}'
manifest "$work/m.json" '{"model": "SIMPLE_RADIAL", "single_camera": true}' "$exhaustive"
manifest "$work/other.json" \
  '{"model": "PINHOLE", "single_camera": false, "default_focal_length_factor": 0.9}' "$exhaustive"
manifest "$work/window.json" '{"model": "SIMPLE_RADIAL", "single_camera": true}' \
  '{"plugin": "window", "options": {"window": 2}}'
tess() {  # tess LOG MANIFEST OUTPUT ARGS...: `run` on the images, log in LOG
  local log=$1 manifest=$2 output=$3
  shift 3
  "$tessera" run --images "$work/images" --output "$output" --manifest "$manifest" --threads 2 \
    "$@" > "$log" 2>&1 || { tail -30 "$log"; fail "run into $output ($log)"; }
}
model_of() { cat "$1"/sparse/0/*.bin | md5sum; }
expect_log() {  # expect_log LOG TEXT
  grep -qF -- "$2" "$1" || { cat "$1"; fail "$1: no line with '$2'"; }
}

# 1. Camera settings.
tess "$work/1.log" "$work/m.json" "$work/out"
before=$(md5sum < "$work/out/sparse/0/cameras.bin")
tess "$work/2.log" "$work/m.json" "$work/out" --camera-K "$work/K.txt"
expect_log "$work/2.log" "extract: camera.K (or --camera-K) changed; re-created the cameras of 6 images as camera 1 (SIMPLE_RADIAL 512x342, focal 460.4 px, user)"
expect_log "$work/2.log" "0 detected with 0 features, 6 reused"
[ "$(md5sum < "$work/out/sparse/0/cameras.bin")" != "$before" ] || fail "--camera-K: cameras.bin unchanged"
tess "$work/2f.log" "$work/m.json" "$work/fresh_K" --camera-K "$work/K.txt"
[ "$(model_of "$work/out")" = "$(model_of "$work/fresh_K")" ] ||
  fail "--camera-K: the model differs from a fresh workspace's"
echo "--camera-K: cameras re-created, features reused, the model of a fresh workspace"
tess "$work/3.log" "$work/other.json" "$work/out"
expect_log "$work/3.log" "extract: camera.K (or --camera-K), camera.default_focal_length_factor, camera.model, camera.single_camera changed; re-created the cameras of 6 images as camera 1 (PINHOLE 512x342, focal 460.8 px, default), camera 2"
expect_log "$work/3.log" "0 detected with 0 features, 6 reused"
tess "$work/3f.log" "$work/other.json" "$work/fresh_other"
[ "$(model_of "$work/out")" = "$(model_of "$work/fresh_other")" ] ||
  fail "camera.model, single_camera, default_focal_length_factor: the model differs from a fresh workspace's"
tess "$work/4.log" "$work/other.json" "$work/out"
if grep -q "re-created the cameras" "$work/4.log"; then fail "unchanged settings re-created the cameras"; fi
echo "camera.model, single_camera, default_focal_length_factor: the same; unchanged: kept"

# 1b. map --camera-K applies K to the workspace's cameras as extract does (features and
#     matches kept, the geometries verified again): the model of a fresh workspace with K,
#     never the old cameras; a K no lens gives on these images is refused, the cameras kept.
tess "$work/8.log" "$work/m.json" "$work/map_K"
map_K() {  # map_K LOG K_FILE: `map --camera-K` on map_K
  "$tessera" map --images "$work/images" --output "$work/map_K" --manifest "$work/m.json" \
    --threads 2 --camera-K "$2" > "$1" 2>&1
}
printf '1e12 0 253.5315\n0 1e12 167.963\n0 0 1\n' > "$work/K_far.txt"
cameras() { sqlite3 "$work/map_K/database.db" 'SELECT hex(params) FROM cameras'; }
before=$(cameras)
map_K "$work/9.log" "$work/K_far.txt"
code=$?
[ "$code" = 2 ] || { cat "$work/9.log"; fail "map --camera-K with fx = 1e12: exit $code, expected 2"; }
[ "$(cameras)" = "$before" ] || fail "a refused --camera-K changed the cameras"
expect_log "$work/9.log" "$work/K_far.txt: fx = 1e+12 px is implausible for the camera of the 6 images of 512x342"
map_K "$work/10.log" "$work/K.txt" || { tail -30 "$work/10.log"; fail "map --camera-K"; }
expect_log "$work/10.log" "re-created the cameras of 6 images as camera 1 (SIMPLE_RADIAL 512x342, focal 460.4 px, user)"
[ "$(model_of "$work/map_K")" = "$(model_of "$work/fresh_K")" ] ||
  fail "map --camera-K: the model differs from a fresh workspace's with K"
echo "map --camera-K: applied to the cameras (matches kept), the model of a fresh workspace; fx = 1e12 refused"

# 2. Pair selection.
tess "$work/5.log" "$work/m.json" "$work/pairs"
tess "$work/6.log" "$work/window.json" "$work/pairs"
expect_log "$work/6.log" "match: 9 pairs from 'window', 0 to match with 'brute_force' (9 already done)"
expect_log "$work/6.log" "verified pairs are left out: the current pair selection did not choose them"
tess "$work/6f.log" "$work/window.json" "$work/fresh_window"
[ "$(model_of "$work/pairs")" = "$(model_of "$work/fresh_window")" ] ||
  fail "window 2 after exhaustive: the model differs from a fresh workspace's"
tess "$work/7.log" "$work/m.json" "$work/pairs"
expect_log "$work/7.log" "match: 15 pairs from 'exhaustive', 0 to match with 'brute_force' (15 already done)"
echo "exhaustive, then window 2: the model of a fresh workspace; back to exhaustive: nothing matched again"
echo "PASS"
