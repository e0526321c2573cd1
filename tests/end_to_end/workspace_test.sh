#!/bin/bash
# The workspace knows its inputs, has one writer at a time, never scans its own output,
# skips images it cannot use, and survives a full disk. On a 512 px copy of the sample
# examples/fountain-P11-small (in the repository), with ORB for speed:
#  1. swapped file contents, and a folder replaced by other images under the same
#     names: the changed images are invalidated (logged) and detected again, their
#     keypoints equal to a fresh workspace's;
#  2. a folder with other names: images no longer there leave the workspace; `map` with
#     an image folder whose files differ from the workspace's is exit 2 naming the file;
#  3. an output folder inside the image folder, and another workspace there, are not
#     scanned (with a log line), so a second run ingests nothing of its own output;
#  4. undecodable, one-pixel-wide, over-the-pixel-limit images and a name with a line
#     break are each skipped with a warning naming them, the run maps the rest, and the
#     next run skips them again without decoding;
#  5. `run` where no pair verifies exits 3;
#  6. a full disk (ulimit -f) exits 2 naming the file, and a rerun completes;
#  7. two concurrent runs: the second is refused naming the first, the first completes;
#     a lock left by kill -9 is taken over with a log line.
# usage: workspace_test.sh TESSERA DOWNSCALE SOURCE_DIR
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
make_image="python3 $source_dir/tests/tools/make_test_image.py"
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/all" 512 90 > /dev/null ||
  fail "downscale"
cat > "$work/m.json" <<'JSON'
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 1500}},
              "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": [{"plugin": "colmap_binary"}]},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15}}
JSON
sed 's/{"plugin": "colmap_binary"}/{"plugin": "colmap_binary"}, {"plugin": "gaussian_splatting"}/' \
  "$work/m.json" > "$work/splat.json"
tess() {  # tess LOG VERB ARGS...: runs tessera with the test manifest, log in LOG
  local log=$1
  shift
  "$tessera" "$@" --manifest "${manifest:-$work/m.json}" --threads 2 > "$log" 2>&1
}
images_of() { sqlite3 "$1/database.db" "SELECT name FROM images ORDER BY name" | tr '\n' ' '; }
keypoints_of() {  # the keypoints of every image, by name
  sqlite3 "$1/database.db" "SELECT name, hex(data) FROM keypoints JOIN images USING (image_id)
                            ORDER BY name" | md5sum
}
registered() { python3 -c 'import json,sys; print(sum(m["num_images"] for m in json.load(open(sys.argv[1]))["models"]))' "$1/mapping_summary.json"; }
subset() {  # subset DIR FIRST LAST: images FIRST..LAST of the sample
  mkdir -p "$1"
  for i in $(seq "$2" "$3"); do cp "$work/all/$(printf %04d "$i").jpg" "$1/"; done
}

# 1. Changed contents.
subset "$work/a" 0 4
tess "$work/a1.log" run --images "$work/a" --output "$work/out_a" || { cat "$work/a1.log"; fail "run a"; }
mv "$work/a/0001.jpg" "$work/tmp.jpg"; mv "$work/a/0002.jpg" "$work/a/0001.jpg"; mv "$work/tmp.jpg" "$work/a/0002.jpg"
tess "$work/a2.log" run --images "$work/a" --output "$work/out_a" || { cat "$work/a2.log"; fail "run a swapped"; }
for name in 0001.jpg 0002.jpg; do
  grep -q "invalidated '$name': it changed since it was ingested" "$work/a2.log" ||
    { cat "$work/a2.log"; fail "no invalidation logged for $name"; }
done
grep -q "3 reused, 0 skipped at decoding or detection, 2 changed and 0 removed" "$work/a2.log" ||
  { cat "$work/a2.log"; fail "swap: counts"; }
tess "$work/a3.log" run --images "$work/a" --output "$work/fresh_a" || fail "fresh run a"
[ "$(keypoints_of "$work/out_a")" = "$(keypoints_of "$work/fresh_a")" ] ||
  fail "swapped files: keypoints differ from a fresh workspace's"
[ "$(registered "$work/out_a")" = 5 ] || fail "swapped files: not all 5 registered"
echo "swapped contents: 2 invalidated and detected again, keypoints as a fresh workspace's"
rm -f "$work"/a/*.jpg
for i in 0 1 2 3 4; do cp "$work/all/$(printf %04d $((i + 5))).jpg" "$work/a/$(printf %04d $i).jpg"; done
tess "$work/a4.log" run --images "$work/a" --output "$work/out_a" || { cat "$work/a4.log"; fail "run replaced"; }
grep -q "0 reused, 0 skipped at decoding or detection, 5 changed" "$work/a4.log" ||
  { cat "$work/a4.log"; fail "replaced folder: counts"; }
rm -rf "$work/fresh_a"
tess "$work/a5.log" run --images "$work/a" --output "$work/fresh_a" || fail "fresh run replaced"
[ "$(keypoints_of "$work/out_a")" = "$(keypoints_of "$work/fresh_a")" ] ||
  fail "replaced folder: keypoints differ from a fresh workspace's"
echo "replaced folder, same names: all 5 invalidated, keypoints as a fresh workspace's"

# 2. Other names.
subset "$work/c" 3 7
tess "$work/c.log" run --images "$work/c" --output "$work/out_a" || { cat "$work/c.log"; fail "run c"; }
[ "$(images_of "$work/out_a")" = "0003.jpg 0004.jpg 0005.jpg 0006.jpg 0007.jpg " ] ||
  fail "other names: the image list is '$(images_of "$work/out_a")'"
grep -q "invalidated '0000.jpg': it is no longer in the image folder" "$work/c.log" ||
  { cat "$work/c.log"; fail "removal not logged"; }
[ "$(sqlite3 "$work/out_a/database.db" "SELECT COUNT(*) FROM matches")" = 10 ] ||
  fail "matches of removed images remain"
echo "other names: the image list is the folder's, removals logged"
tess "$work/c2.log" map --output "$work/out_a" --images "$work/a"
code=$?
[ "$code" = 2 ] || { cat "$work/c2.log"; fail "map with other images: exit $code, expected 2"; }
grep -q "$work/a/0003.jpg: changed since the workspace ingested it" "$work/c2.log" ||
  { cat "$work/c2.log"; fail "map with other images: message"; }
echo "map with an image folder whose files differ: exit 2 naming the file"

# 3. Output inside the image folder.
subset "$work/d" 0 4
manifest="$work/splat.json" tess "$work/d1.log" run --images "$work/d" --output "$work/d/out" ||
  { cat "$work/d1.log"; fail "run d"; }
cp -r "$work/out_a" "$work/d/old_workspace"
manifest="$work/splat.json" tess "$work/d2.log" run --images "$work/d" --output "$work/d/out" ||
  { cat "$work/d2.log"; fail "run d again"; }
grep -q "Skipped the folder 'out': it is the output folder of this run" "$work/d2.log" ||
  { cat "$work/d2.log"; fail "output folder not skipped"; }
grep -q "Skipped the folder 'old_workspace': it is a Tessera workspace" "$work/d2.log" ||
  { cat "$work/d2.log"; fail "workspace not skipped"; }
[ "$(images_of "$work/d/out")" = "0000.jpg 0001.jpg 0002.jpg 0003.jpg 0004.jpg " ] ||
  fail "output fed input: $(images_of "$work/d/out")"
echo "output inside the image folder: not scanned"

# 4. Images that cannot be used.
subset "$work/e" 0 4
$make_image corrupt "$work/e/corrupt.png"
$make_image thin "$work/e/thin.png"
$make_image huge "$work/e/huge.png"
cp "$work/all/0005.jpg" "$work/e/line
break.jpg"
tess "$work/e1.log" run --images "$work/e" --output "$work/out_e" || { cat "$work/e1.log"; fail "run e"; }
for expected in "Skipped 'corrupt.png': cannot decode the image" "Skipped 'thin.png': " \
  "Skipped 'huge.png': 100000x100000 pixels is over the limit of 250000000" \
  "the name contains a line break"; do
  grep -q "$expected" "$work/e1.log" || { cat "$work/e1.log"; fail "no warning: $expected"; }
done
[ "$(registered "$work/out_e")" = 5 ] || fail "bad images: not all 5 good images registered"
tess "$work/e2.log" run --images "$work/e" --output "$work/out_e" || { cat "$work/e2.log"; fail "rerun e"; }
grep -q "Skipped 'corrupt.png' (as in an earlier run, the file is unchanged)" "$work/e2.log" ||
  { cat "$work/e2.log"; fail "the skip was not recorded"; }
echo "bad images: each skipped with a warning naming it, the rest mapped, the skip recorded"

# 5. No verified pair: exit 3.
mkdir -p "$work/f"
$make_image flat "$work/f/a.png"
$make_image flat "$work/f/b.png"
tess "$work/f.log" run --images "$work/f" --output "$work/out_f"
code=$?
[ "$code" = 3 ] || { cat "$work/f.log"; fail "no verified pair: exit $code, expected 3"; }
echo "no verified pair: exit 3"

# 6. Disk full.
( trap '' XFSZ; ulimit -f 200; exec "$tessera" run --images "$work/d" --output "$work/out_g" \
    --manifest "$work/m.json" --threads 2 ) > "$work/g1.log" 2>&1
code=$?
[ "$code" = 2 ] || { cat "$work/g1.log"; fail "disk full: exit $code, expected 2"; }
grep -q "\[error\] .*$work/out_g/.*disk full" "$work/g1.log" || { cat "$work/g1.log"; fail "disk full: message"; }
tess "$work/g2.log" run --images "$work/d" --output "$work/out_g" || { cat "$work/g2.log"; fail "rerun after disk full"; }
[ "$(registered "$work/out_g")" = 5 ] || fail "disk full: the rerun did not register 5"
echo "disk full: exit 2 naming $(grep -o "$work/out_g/[^ ']*" "$work/g1.log" | head -1 | sed "s|$work/||"), rerun completes"

# 7. Two writers.
TESSERA_TEST_PAUSE=workspace.locked:1 "$tessera" run --images "$work/all" --output "$work/out_h" \
  --manifest "$work/m.json" --threads 2 > "$work/h1.log" 2>&1 &
first=$!
wait_until_paused $first
"$tessera" run --images "$work/all" --output "$work/out_h" > "$work/h2.log" 2>&1
code=$?
kill -CONT $first
[ "$code" = 2 ] || { cat "$work/h2.log"; fail "second writer: exit $code, expected 2"; }
grep -q "workspace $work/out_h is in use by process $first (since " "$work/h2.log" ||
  { cat "$work/h2.log"; fail "second writer: message"; }
wait $first || { cat "$work/h1.log"; fail "the first writer failed"; }
[ "$(registered "$work/out_h")" = 11 ] || fail "the first writer registered $(registered "$work/out_h") of 11"
echo "two writers: the second refused naming the first, the first registered 11 of 11"
TESSERA_TEST_PAUSE=workspace.locked:1 "$tessera" run --images "$work/all" --output "$work/out_i" \
  --manifest "$work/m.json" --threads 2 > "$work/i1.log" 2>&1 &
victim=$!
wait_until_paused $victim
kill -9 $victim; wait $victim 2> /dev/null
tess "$work/i2.log" extract --images "$work/all" --output "$work/out_i" || { cat "$work/i2.log"; fail "extract after kill -9"; }
grep -q "taking over the lock left by process $victim" "$work/i2.log" ||
  { cat "$work/i2.log"; fail "stale lock not reported"; }
echo "kill -9: the next run takes the lock over with a log line"
echo "PASS"
