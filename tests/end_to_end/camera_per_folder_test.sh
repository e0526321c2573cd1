#!/bin/bash
# One camera per folder (camera.per_folder, --camera-per-folder). On a 512 px copy of 6
# images of the sample examples/fountain-P11-small (in the repository), split into two
# folders of same-size images, with ORB for speed:
#  1. `run --camera-per-folder`: the workspace and the exported model (colmap_text) have
#     two cameras, each with its own intrinsics, every image on its folder's camera, and
#     the log names each camera's folder;
#  2. the same workspace without the flag: the cameras are re-created (logged, naming
#     camera.per_folder) as one camera, and the model is byte for byte that of a fresh
#     workspace without the flag;
#  3. the folders at two image sizes (512 and 480 px), as the issue's test names it: a
#     camera per folder, at its folder's size.
# usage: camera_per_folder_test.sh TESSERA DOWNSCALE SOURCE_DIR
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/all" 512 90 > /dev/null ||
  fail "downscale"
mkdir -p "$work/images/a" "$work/images/b"
for i in 0 2 4; do cp "$work/all/000$i.jpg" "$work/images/a/"; done
for i in 1 3 5; do cp "$work/all/000$i.jpg" "$work/images/b/"; done
cat > "$work/m.json" <<JSON
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 1500}},
              "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": [{"plugin": "colmap_text"}]},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15}}
JSON
tess() {  # tess LOG OUTPUT ARGS...: `run` on the images, log in LOG
  local log=$1 output=$2
  shift 2
  "$tessera" run --images "$work/images" --output "$output" --manifest "$work/m.json" \
    --threads 2 "$@" > "$log" 2>&1 || { tail -30 "$log"; fail "run into $output ($log)"; }
}
expect_log() {  # expect_log LOG TEXT
  grep -qF -- "$2" "$1" || { cat "$1"; fail "$1: no line with '$2'"; }
}
# The cameras of a model (cameras.txt: ID MODEL W H PARAMS...), one line each.
cameras_of() { grep -v '^#' "$1/sparse/0/cameras.txt"; }
# "NAME CAMERA_ID" for each image of a model (the first of the two lines per image).
image_cameras_of() {
  grep -v '^#' "$1/sparse/0/images.txt" | awk 'NR % 2 == 1 { print $10, $9 }' | sort
}

# 1. Per folder.
tess "$work/1.log" "$work/out" --camera-per-folder
expect_log "$work/1.log" "extract: 2 cameras by folder (camera.per_folder): camera 1 from 'a', camera 2 from 'b'"
[ "$(cameras_of "$work/out" | wc -l)" = 2 ] || {
  cameras_of "$work/out"
  fail "--camera-per-folder: the model does not have two cameras"
}
# Each camera refined on its own images: the two focal lengths differ.
[ "$(cameras_of "$work/out" | awk '{ print $5 }' | sort -u | wc -l)" = 2 ] || {
  cameras_of "$work/out"
  fail "--camera-per-folder: the two cameras have the same focal length"
}
expected="a/0000.jpg 1
a/0002.jpg 1
a/0004.jpg 1
b/0001.jpg 2
b/0003.jpg 2
b/0005.jpg 2"
[ "$(image_cameras_of "$work/out")" = "$expected" ] || {
  image_cameras_of "$work/out"
  fail "--camera-per-folder: an image is not on its folder's camera (or is not registered)"
}
python3 - "$work/out/database.db" <<'PY' || fail "--camera-per-folder: the workspace's cameras"
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
rows = sorted(db.execute("SELECT name, camera_id FROM images"))
folders = {}
for name, camera in rows:
    folders.setdefault(name.split("/")[0], set()).add(camera)
assert len(db.execute("SELECT camera_id FROM cameras").fetchall()) == 2, "not two cameras"
assert folders["a"] != folders["b"] and all(len(c) == 1 for c in folders.values()), folders
PY
echo "--camera-per-folder: two cameras, one per folder, each with its own focal length"

# 2. Without the flag: one camera again, as a fresh workspace makes it.
tess "$work/2.log" "$work/out"
expect_log "$work/2.log" "extract: camera.per_folder changed; re-created the cameras of 6 images as camera 1 (SIMPLE_RADIAL 512x342"
expect_log "$work/2.log" "0 detected with 0 features, 6 reused"
[ "$(cameras_of "$work/out" | wc -l)" = 1 ] || fail "without the flag: not one camera"
tess "$work/2f.log" "$work/fresh"
[ "$(cat "$work"/out/sparse/0/*.txt | md5sum)" = "$(cat "$work"/fresh/sparse/0/*.txt | md5sum)" ] ||
  fail "without the flag: the model differs from a fresh workspace's"
echo "without the flag: the cameras re-created as one, the model of a fresh workspace"

# 3. Folders of different image sizes.
"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/all480" 480 90 > /dev/null ||
  fail "downscale to 480 px"
mkdir -p "$work/sizes/a" "$work/sizes/b"
cp "$work"/images/a/*.jpg "$work/sizes/a/"
for i in 1 3 5; do cp "$work/all480/000$i.jpg" "$work/sizes/b/"; done
if ! "$tessera" run --images "$work/sizes" --output "$work/sizes_out" --manifest "$work/m.json" \
  --threads 2 --camera-per-folder > "$work/3.log" 2>&1; then
  tail -30 "$work/3.log"
  fail "run of two sizes"
fi
[ "$(cameras_of "$work/sizes_out" | awk '{ print $1, $3, $4 }')" = "1 512 342
2 480 320" ] || {
  cameras_of "$work/sizes_out"
  fail "two sizes: not camera 1 at 512x342 and camera 2 at 480x320"
}
[ "$(image_cameras_of "$work/sizes_out")" = "$expected" ] || {
  image_cameras_of "$work/sizes_out"
  fail "two sizes: an image is not on its folder's camera (or is not registered)"
}
echo "two folders of different sizes: a camera each, at its folder's size"
