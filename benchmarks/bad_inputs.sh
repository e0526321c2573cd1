#!/bin/bash
# Runs Tessera on a collection of bad inputs and classifies each outcome:
#   crash               exit code other than 0, 2 and 3 (1 = internal error, or a signal),
#                       unless the case expects it (a deliberately broken plugin's 1 or 4)
#   silent wrong output exit 0 (or the expected code) but the result is wrong: a bad
#                       file not named in a warning, a wrong image list, stale features
#   unclear message     the expected failure, but the error line does not name the file,
#                       key or folder at fault
#   other mismatch      the wrong exit code without a crash
# On a 512 px copy of examples/fountain-P11-small with ORB (seconds per case).
# usage: benchmarks/bad_inputs.sh [TESSERA]
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
tessera=${1:-$root/build/bin/tessera}
make_image="python3 $root/tests/tools/make_test_image.py"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$root/build/bin/tessera_test_downscale" "$root/examples/fountain-P11-small/images" "$work/all" 512 90 \
  > /dev/null || { echo "downscale failed (build tessera_test_downscale)"; exit 1; }
cat > "$work/m.json" <<'JSON'
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 1500}},
              "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": [{"plugin": "colmap_binary"}]},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15}}
JSON
tried=0 crashes=0 silent=0 unclear=0 other=0
subset() {  # subset DIR N: the first N images of the sample
  mkdir -p "$1"
  for f in $(ls "$work/all" | sort | head -n "$2"); do cp "$work/all/$f" "$1/"; done
}
registered() {
  python3 -c 'import json,sys; print(sum(m["num_images"] for m in json.load(open(sys.argv[1]))["models"]))' \
    "$1/mapping_summary.json" 2> /dev/null || echo 0
}
# check NAME EXPECTED_CODE MESSAGE_REGEX RESULT_CHECK -- COMMAND...
#   MESSAGE_REGEX: must match the output (an error line naming what is wrong, or the
#   warning naming the skipped file); RESULT_CHECK: a shell test of the result, "" none.
check() {
  local name=$1 expected=$2 pattern=$3 result_check=$4
  shift 5
  tried=$((tried + 1))
  "$@" > "$work/case.log" 2>&1
  local code=$?
  local verdict=ok
  if [ "$code" != 0 ] && [ "$code" != 2 ] && [ "$code" != 3 ] && [ "$code" != "$expected" ]; then
    verdict=crash; crashes=$((crashes + 1))
  elif [ "$code" != "$expected" ]; then
    if [ "$code" = 0 ]; then verdict="silent wrong output"; silent=$((silent + 1));
    else verdict="other mismatch"; other=$((other + 1)); fi
  elif ! grep -qE -- "$pattern" "$work/case.log"; then
    if [ "$expected" = 0 ]; then verdict="silent wrong output"; silent=$((silent + 1));
    else verdict="unclear message"; unclear=$((unclear + 1)); fi
  elif [ -n "$result_check" ] && ! eval "$result_check"; then
    verdict="silent wrong output"; silent=$((silent + 1))
  fi
  printf "%-44s exit %s  %s\n" "$name" "$code" "$verdict"
  [ "$verdict" = ok ] || sed 's/^/    /' "$work/case.log" | tail -3
}
t() { "$tessera" "$@" --threads 2; }
run_m() { t run --manifest "$work/m.json" "$@"; }

# Manifests.
mkdir -p "$work/manifest_dir"
check "manifest is a folder" 2 "manifest_dir: cannot read the manifest: it is a folder" "" -- \
  t run --images "$work/all" --output "$work/o1" --manifest "$work/manifest_dir"
echo '{"verification": {"max_error_px": 1e400}}' > "$work/overflow.json"
check "number 1e400" 2 "overflow.json: invalid JSON at line 1 \(key 'max_error_px'\)" "" -- \
  t run --images "$work/all" --output "$work/o2" --manifest "$work/overflow.json"
echo '{"pipeline": {' > "$work/broken.json"
check "truncated JSON" 2 "broken.json: invalid JSON: .*line 2" "" -- \
  t run --images "$work/all" --output "$work/o3" --manifest "$work/broken.json"
echo '{"pipeline": {"detector": {"plugin": "sfit"}}}' > "$work/typo.json"
check "misspelt plugin" 2 "pipeline.detector.plugin: no detector plugin 'sfit'; did you mean 'sift'" "" -- \
  t run --images "$work/all" --output "$work/o4" --manifest "$work/typo.json"
check "missing manifest" 2 "nonexistent.json: cannot read the manifest" "" -- \
  t run --images "$work/all" --output "$work/o5" --manifest "$work/nonexistent.json"
echo '{"threads": -3}' > "$work/threads.json"
check "negative threads" 2 "threads.json: threads = -3 is out of range" "" -- \
  t run --images "$work/all" --output "$work/o6" --manifest "$work/threads.json"

# Exporter paths.
mkdir -p "$work/x/y"
echo '{"pipeline": {"exporters": [{"plugin": "transforms_json", "options": {"file": "../../escape.json"}}]}}' > "$work/escape_manifest.json"
check "exporter file ../../escape.json" 2 "pipeline.exporters\[0\].options.file: '../../escape.json' leaves the output folder" \
  '[ ! -e "$work/x/escape.json" ] && [ ! -e "$work/escape.json" ]' -- \
  t run --images "$work/all" --output "$work/x/y/out" --manifest "$work/escape_manifest.json"
echo '{"pipeline": {"exporters": [{"plugin": "gaussian_splatting", "options": {"folder": "/tmp/tessera_escape"}}]}}' > "$work/absolute.json"
check "exporter folder absolute" 2 "pipeline.exporters\[0\].options.folder: '/tmp/tessera_escape' is absolute" "" -- \
  t run --images "$work/all" --output "$work/o7" --manifest "$work/absolute.json"

# Image folders.
check "image folder missing" 2 "no_such_folder: the image folder does not exist" "" -- \
  run_m --images "$work/no_such_folder" --output "$work/o8"
subset "$work/one" 1
check "one image" 2 "one: 1 usable image\(s\); at least 2 are needed" "" -- \
  run_m --images "$work/one" --output "$work/o9"
mkdir -p "$work/empty_folder"
check "no images" 2 "empty_folder: 0 usable image\(s\)" "" -- \
  run_m --images "$work/empty_folder" --output "$work/o10"
check "images = output" 2 "the image folder is the output folder of this run" "" -- \
  run_m --images "$work/all" --output "$work/all"

# Bad image files beside 5 good ones: each named in a warning, the 5 mapped.
bad_file_case() {  # NAME FILE MAKE_COMMAND WARNING_REGEX
  local dir="$work/bad_$tried"
  subset "$dir" 5
  eval "$3"
  check "$1" 0 "$4" '[ "$(registered "$dir/out")" = 5 ]' -- run_m --images "$dir" --output "$dir/out"
}
bad_file_case "undecodable PNG (valid chunks)" corrupt.png '$make_image corrupt "$dir/corrupt.png"' "Skipped 'corrupt.png': cannot decode"
bad_file_case "1 px wide image" thin.png '$make_image thin "$dir/thin.png"' "Skipped 'thin.png'"
bad_file_case "1 px high image" thin.png '$make_image thin-h "$dir/thin.png"' "Skipped 'thin.png'"
bad_file_case "header claims 10 gigapixels" huge.png '$make_image huge "$dir/huge.png"' "Skipped 'huge.png': 100000x100000 pixels is over the limit"
bad_file_case "line break in a name" "" 'cp "$work/all/0010.jpg" "$dir/a
b.jpg"' "Skipped 'a..b.jpg': the name contains a line break"
bad_file_case "empty .jpg" "" ': > "$dir/empty.jpg"' "Skipped 'empty.jpg': the file is empty"
bad_file_case "text named .jpg" "" 'echo text > "$dir/notes.jpg"' "Skipped 'notes.jpg': not a JPEG, PNG or TIFF"
bad_file_case "truncated JPEG" "" 'head -c 9000 "$work/all/0010.jpg" > "$dir/cut.jpg"' "Skipped 'cut.jpg': truncated JPEG"
bad_file_case "noise image" "" '$make_image noise "$dir/noise.png"' "noise.png is in no model|Skipped 'noise.png'"

# Nothing verifies: exit 3.
mkdir -p "$work/flat"
$make_image flat "$work/flat/a.png"; $make_image flat "$work/flat/b.png"
check "no verified pair (flat images)" 3 "no model could be built" "" -- \
  run_m --images "$work/flat" --output "$work/flat_out"

# Workspaces.
subset "$work/w" 5
run_m --images "$work/w" --output "$work/w_out" > /dev/null 2>&1
mv "$work/w/0001.jpg" "$work/t.jpg"; mv "$work/w/0002.jpg" "$work/w/0001.jpg"; mv "$work/t.jpg" "$work/w/0002.jpg"
fresh_keypoints() { sqlite3 "$1/database.db" "SELECT name, hex(data) FROM keypoints JOIN images USING (image_id) ORDER BY name" | md5sum; }
run_m --images "$work/w" --output "$work/w_fresh" > /dev/null 2>&1
check "swapped file contents" 0 "invalidated '0001.jpg'" \
  '[ "$(fresh_keypoints "$work/w_out")" = "$(fresh_keypoints "$work/w_fresh")" ]' -- \
  run_m --images "$work/w" --output "$work/w_out"
subset "$work/w2" 8
rm "$work"/w2/000[0-2].jpg
check "folder with other names" 0 "invalidated '0000.jpg': it is no longer in the image folder" \
  '[ "$(sqlite3 "$work/w_out/database.db" "SELECT COUNT(*) FROM images")" = 5 ]' -- \
  run_m --images "$work/w2" --output "$work/w_out"
subset "$work/nested" 5
run_m --images "$work/nested" --output "$work/nested/out" > /dev/null 2>&1
check "output inside the image folder" 0 "Skipped the folder 'out': it is the output folder" \
  '[ "$(sqlite3 "$work/nested/out/database.db" "SELECT COUNT(*) FROM images")" = 5 ]' -- \
  run_m --images "$work/nested" --output "$work/nested/out"
# Issue 60: an export put inside the image folder holds only the outputs ledger (no lock,
# no database): its undistorted copies were ingested as more photos (22 images, not 11).
subset "$work/exp_in" 11
run_m --images "$work/exp_in" --output "$work/exp_in_ws" > /dev/null 2>&1
"$tessera" export --model "$work/exp_in_ws/sparse/0" --format gaussian_splatting \
  --images "$work/exp_in" --output "$work/exp_in/out" > /dev/null 2>&1
check "a 3DGS export inside the image folder" 0 "Skipped the folder 'out': it holds Tessera's outputs" \
  '[ -n "$(ls "$work/exp_in/out/gaussian_splatting/images")" ] && [ "$(sqlite3 "$work/exp_in_ws2/database.db" "SELECT COUNT(*) FROM images")" = 11 ]' -- \
  run_m --images "$work/exp_in" --output "$work/exp_in_ws2"
mkdir -p "$work/garbage_db"; head -c 5000 /dev/urandom > "$work/garbage_db/database.db"
check "database.db not SQLite" 2 "garbage_db/database.db' is not a valid SQLite database" "" -- \
  run_m --images "$work/w" --output "$work/garbage_db"
cp -r "$work/w_out" "$work/mixed"
sqlite3 "$work/mixed/database.db" "DELETE FROM matches; DELETE FROM two_view_geometries;
  UPDATE descriptors SET cols = 128, rows = rows / 4 WHERE image_id = (SELECT MIN(image_id) FROM images)"
check "descriptors of two widths (match)" 2 "mixed/database.db: the workspace holds descriptors of 2 widths \(32, 128 bytes\)" "" -- \
  t match --output "$work/mixed" --manifest "$work/m.json"
check "map without a workspace" 2 "no_workspace/database.db: no workspace database" "" -- \
  t map --output "$work/no_workspace" --manifest "$work/m.json"
echo "1 2 3" > "$work/K_bad.txt"
check "malformed --camera-K" 2 "K_bad.txt: expected 9 numbers" "" -- \
  run_m --images "$work/w" --output "$work/o11" --camera-K "$work/K_bad.txt"
( trap '' XFSZ; ulimit -f 200; exec "$tessera" run --images "$work/w" --output "$work/full_disk" \
    --manifest "$work/m.json" --threads 2 ) > "$work/disk.log" 2>&1
disk_code=$?
check "disk full (ulimit -f), then a rerun" 0 "" '[ "$disk_code" = 2 ] && grep -q "full_disk/.*disk full" "$work/disk.log" && [ "$(registered "$work/full_disk")" = 5 ]' -- \
  run_m --images "$work/w" --output "$work/full_disk"
subset "$work/c" 11
"$tessera" run --manifest "$work/m.json" --threads 2 --images "$work/c" --output "$work/c_out" > "$work/first.log" 2>&1 &
first=$!
for _ in $(seq 1 200); do [ -s "$work/c_out/.tessera.lock" ] && break; sleep 0.05; done
check "a second writer on the same output" 2 "workspace $work/c_out is in use by process $first \(since " "" -- \
  t run --images "$work/c" --output "$work/c_out"
wait $first; first_code=$?
tried=$((tried + 1))
if [ "$first_code" != 0 ] || [ "$(registered "$work/c_out")" != 11 ]; then
  echo "the first writer: exit $first_code, $(registered "$work/c_out") registered  silent wrong output"
  silent=$((silent + 1))
else
  printf "%-44s exit %s  %s\n" "the first writer, meanwhile" 0 ok
fi

# Models and ground truth eval cannot judge, and non-finite numbers in models: four
# images at distinct centres, looking down z, and their ground truth (transforms.json).
mkdir -p "$work/eval/model"
echo "1 SIMPLE_PINHOLE 640 480 500 320 240" > "$work/eval/model/cameras.txt"
printf '1 1 0 0 0 0 0 0 1 a.jpg\n\n2 1 0 0 0 -1 0 0 1 b.jpg\n\n3 1 0 0 0 0 -1 0 1 c.jpg\n\n4 1 0 0 0 0 0 -1 1 d.jpg\n\n' \
  > "$work/eval/model/images.txt"
: > "$work/eval/model/points3D.txt"
gt() {  # gt NAME NAME=CX,CY,CZ[,R00..R22]...: a transforms.json of these frames
  python3 - "$work/eval/$1.json" "${@:2}" <<'PY'
import json, sys
frames = []
for spec in sys.argv[2:]:
    name, numbers = spec.split("=")
    v = [float(x) for x in numbers.split(",")]
    r = v[3:] if len(v) > 3 else [1, 0, 0, 0, -1, 0, 0, 0, -1]
    frames.append({"file_path": "images/" + name, "transform_matrix":
                   [r[0:3] + [v[0]], r[3:6] + [v[1]], r[6:9] + [v[2]], [0, 0, 0, 1]]})
json.dump({"frames": frames}, open(sys.argv[1], "w"))
PY
}
gt good a.jpg=0,0,0 b.jpg=1,0,0 c.jpg=0,1,0 d.jpg=0,0,1
check "eval: a model and its own ground truth" 0 "registered: 4/4" "" -- \
  "$tessera" eval "$work/eval/model" "$work/eval/good.json"
gt duplicate a.jpg=0,0,0 b.jpg=1,0,0 c.jpg=0,1,0 d.jpg=0,0,1 a.jpg=5,5,5
check "eval: duplicate frame name" 2 "duplicate.json: frames\[4\] \(images/a.jpg\) has the image name a.jpg of frames\[0\]" "" -- \
  "$tessera" eval "$work/eval/model" "$work/eval/duplicate.json"
gt same a.jpg=1,1,1 b.jpg=1,1,1 c.jpg=1,1,1 d.jpg=1,1,1
check "eval: all centres identical" 2 "same.json: the ground truth places the 4 images in both at only 1 distinct camera centre" "" -- \
  "$tessera" eval "$work/eval/model" "$work/eval/same.json"
gt zero a.jpg=0,0,0 b.jpg=1,0,0,0,0,0,0,0,0,0,0,0 c.jpg=0,1,0 d.jpg=0,0,1
check "eval: zero rotation matrix" 2 "zero.json: frames\[1\] \(images/b.jpg\): the rotation is not a rotation matrix" "" -- \
  "$tessera" eval "$work/eval/model" "$work/eval/zero.json"
gt far a.jpg=0,0,0 b.jpg=1e308,0,0 c.jpg=0,1,0 d.jpg=0,0,1
check "eval: 1e308 translation" 2 "far.json: frames\[1\] \(images/b.jpg\): the camera centre \(1e\+308, 0, 0\) lies beyond" "" -- \
  "$tessera" eval "$work/eval/model" "$work/eval/far.json"
cp -r "$work/eval/model" "$work/eval/nan_model"
sed -i 's/^2 1 0 0 0 -1 0 0/2 1 0 0 0 nan 0 0/' "$work/eval/nan_model/images.txt"
check "eval: NaN pose in the model" 2 "nan_model/images.txt line 3: 'nan' is not a finite translation component" "" -- \
  "$tessera" eval "$work/eval/nan_model" "$work/eval/good.json"
cp -r "$work/eval/model" "$work/eval/nan_camera"
echo "1 SIMPLE_PINHOLE 640 480 nan 320 240" > "$work/eval/nan_camera/cameras.txt"
check "export of a model with a NaN focal length" 2 "nan_camera/cameras.txt line 1: 'nan' is not a finite camera parameter" \
  '[ ! -e "$work/eval/nan_export" ]' -- \
  "$tessera" export --model "$work/eval/nan_camera" --format transforms_json --output "$work/eval/nan_export"
"$tessera" -q export --model "$work/eval/model" --format colmap_binary --output "$work/eval/bin" > /dev/null 2>&1
python3 -c 'import struct, sys; p = sys.argv[1]; b = bytearray(open(p, "rb").read())
b[44:52] = struct.pack("<d", float("inf")); open(p, "wb").write(b)' "$work/eval/bin/sparse/0/images.bin"
check "binary model with an infinite translation" 2 "images.bin is truncated or malformed at byte 44: the translation of image 1: inf is not a finite number" "" -- \
  "$tessera" eval "$work/eval/bin/sparse/0" "$work/eval/good.json"

# Messages that name the file, key, plugin or image.
printf '2759.48 0 1520.69\n0 2764.16 1006.81\n0 0 1\n1\n' > "$work/K10.txt"
check "K file with 10 numbers" 2 "K10.txt: expected 9 numbers \(a 3x3 matrix\), found 10" "" -- \
  run_m --images "$work/w" --output "$work/o12" --camera-K "$work/K10.txt"
printf 'nan 0 1520.69\n0 2764.16 1006.81\n0 0 1\n' > "$work/Knan.txt"
check "K file with nan" 2 "Knan.txt: 'nan' is not a finite number \(number 1 of the file\)" "" -- \
  run_m --images "$work/w" --output "$work/o13" --camera-K "$work/Knan.txt"
echo '{"pipeline": {"detector": {"plugin": "orb"}}, "pipeline": {"matcher": {"plugin": "flann"}}}' > "$work/dup_key.json"
check "duplicate \"pipeline\" key" 2 "dup_key.json: pipeline: the key appears twice in one object" "" -- \
  t run --images "$work/w" --output "$work/o14" --manifest "$work/dup_key.json"
check "--threads -1" 2 "--threads: Value -1 not in range 0 to 1024$" "" -- \
  "$tessera" run --images "$work/w" --output "$work/o15" --threads -1
check "gui --frames -1" 2 "--frames: Value -1 is not a whole number of at least 1$" "" -- \
  "$tessera" gui --screenshot "$work/s.png" --frames -1
cp -r "$work/w_out" "$work/fisheye_db"
sqlite3 "$work/fisheye_db/database.db" "UPDATE cameras SET model = 10"
check "database camera model id 10" 2 "camera model id 10, which Tessera does not support \(it knows .*5 OPENCV_FISHEYE, 8 SIMPLE_RADIAL_FISHEYE\)" "" -- \
  t map --output "$work/fisheye_db" --manifest "$work/m.json"
failing="$root/build/test_plugins/failing"
if [ -d "$failing" ]; then
  plugin_manifest() {  # DETECTOR_OPTIONS MATCHER_OPTIONS: the failing plugins of tests/plugins
    echo "{\"plugin_paths\": [\"$failing\"], \"pipeline\": {
      \"detector\": {\"plugin\": \"failing_detector\", \"options\": $1},
      \"pair_selector\": {\"plugin\": \"failing_pair_selector\"},
      \"matcher\": {\"plugin\": \"failing_matcher\", \"options\": $2},
      \"bundle_adjuster\": {\"plugin\": \"failing_bundle_adjuster\"}}}"
  }
  plugin_manifest '{}' '{"fail": "bad_indices"}' > "$work/bad_indices.json"
  check "matcher returns indices beyond the keypoints" 1 "plugin 'failing_matcher' failed while matching images [0-9]+.jpg and [0-9]+.jpg: it returned match" "" -- \
    t run --images "$work/w" --output "$work/o16" --manifest "$work/bad_indices.json"
  plugin_manifest '{"fail": "exit"}' '{}' > "$work/exit.json"
  check "detector calls exit(0)" 4 "plugin 'failing_detector' ended the process \(exit\) while detecting image" \
    '[ ! -e "$work/o17/sparse" ]' -- t run --images "$work/w" --output "$work/o17" --manifest "$work/exit.json"
else
  echo "(the failing test plugins are not built: $failing; plugin cases skipped)"
fi

# Names from outside: image names of models, databases and videos become paths; Slurm
# values are written into batch scripts.
"$tessera" export --model "$work/w_out/sparse/0" --format colmap_text --output "$work/text_model" > /dev/null 2>&1
bad_name_model() {  # DIR NAME: the text model with its first image renamed NAME
  mkdir -p "$1"; cp "$work/text_model/sparse/0"/*.txt "$1/"
  NAME="$2" python3 -c 'import os, sys
p = sys.argv[1] + "/images.txt"; lines = open(p).read().split("\n")
first = next(i for i, l in enumerate(lines) if l and not l.startswith("#"))
lines[first] = " ".join(lines[first].split(" ")[:9] + [os.environ["NAME"]])
open(p, "w").write("\n".join(lines))' "$1"
}
cp "$work/w/0003.jpg" "$work/victim.jpg"
bad_name_model "$work/abs_model" "$work/victim.jpg"
check "model image name absolute (3DGS export)" 2 "abs_model/images.txt line [0-9]+: image [0-9]+: the image name '$work/victim.jpg' is an absolute path" \
  'cmp -s "$work/victim.jpg" "$work/w/0003.jpg"' -- \
  "$tessera" export --model "$work/abs_model" --format gaussian_splatting --images "$work/w" --output "$work/abs_out"
mkdir -p "$work/deep/er"; cp "$work/w/0003.jpg" "$work/deep/escaped.jpg"
bad_name_model "$work/dotdot_model" "../escaped.jpg"
check "model image name ../ (3DGS export)" 2 "dotdot_model/images.txt line [0-9]+: image [0-9]+: the image name '../escaped.jpg' has a '..' component" \
  '[ ! -e "$work/deep/out/gaussian_splatting/escaped.jpg" ] && [ ! -e "$work/deep/out/escaped.jpg" ]' -- \
  "$tessera" export --model "$work/dotdot_model" --format gaussian_splatting --images "$work/deep/er" --output "$work/deep/out"
cp -r "$work/w_out" "$work/nl_db"
sqlite3 "$work/nl_db/database.db" "UPDATE images SET name = 'a' || char(10) || 'b.jpg' WHERE image_id = (SELECT MIN(image_id) FROM images)"
check "database image name with a line break" 2 "nl_db/database.db': image [0-9]+: the image name 'a\\\\nb.jpg' contains a line break" "" -- \
  t map --output "$work/nl_db" --manifest "$work/m.json"
echo "not a video" > "$work/clip
rm.mp4"
check "video name with a line break" 2 "video '$work/clip\\\\nrm.mp4': the image name 'clip\\\\nrm/frame_" \
  '[ ! -e "$work/v_out/video_frames" ]' -- \
  run_m --video "$work/clip
rm.mp4" --output "$work/v_out"
for option in --partition --sbatch-arg --time; do
  check "slurm $option with a line break" 2 "$option 'x\\\\ntouch .*pwned': holds a control character" \
    '[ ! -e "$work/s_out" ] && [ ! -e "$work/pwned" ]' -- \
    t slurm --images "$work/w" --output "$work/s_out" --workers 2 --dry-run --manifest "$work/m.json" \
      "$option" "x
touch $work/pwned"
done
check "slurm --output with a line break" 2 "--output '$work/s_out\\\\ntouch .*pwned': holds a control character" \
  '[ ! -e "$work/s_out" ] && [ ! -e "$work/pwned" ]' -- \
  t slurm --images "$work/w" --output "$work/s_out
touch $work/pwned" --workers 2 --dry-run --manifest "$work/m.json"
odd="$work/it's \$HOME \`id\` \"q\" #1 100%"
check "slurm --output with quotes, \$, \` and #" 0 "slurm: wrote" \
  '[ "$(sed -n "s/^exec [^ ]* /printf \"%s\\\\n\" /p" "$odd/slurm/map.sh" | bash | sed -n "/^--output$/{n;p}")" = "$odd" ] && grep -q "^#SBATCH --output=\"" "$odd/slurm/map.sh"' -- \
  t slurm --images "$work/w" --output "$odd" --workers 2 --dry-run --manifest "$work/m.json"

# Calibration: a K is checked as input wherever it is given; a recipe that holds the
# intrinsics (camera.require_calibration) refuses what is wrong (exit 2), any other run
# warns; `map --camera-K` applies it or refuses it.
python3 - "$work/m.json" "$work/held.json" <<'PY'
import json, sys
manifest = json.load(open(sys.argv[1]))
manifest["camera"]["require_calibration"] = True
json.dump(manifest, open(sys.argv[2], "w"))
PY
k_file() { printf '%s %s %s\n%s %s %s\n%s %s 1\n' "${@:2}" > "$work/$1"; }  # NAME 8 NUMBERS
k_file K512.txt 459.9135 0 253.5315 0 460.916 167.963 0 0
k_file K_skew.txt 459.9135 150 253.5315 0 460.916 167.963 0 0
k_file K_row.txt 459.9135 0 253.5315 0 460.916 167.963 5 7
k_file K_tenth.txt 459.9135 0 253.5315 0 45.9916 167.963 0 0
k_file K1024.txt 919.827 0 507.063 0 921.832 335.926 0 0
k_file K_tiny.txt 1e-9 0 253.5315 0 1e-9 167.963 0 0
k_file K_huge.txt 1e12 0 253.5315 0 1e12 167.963 0 0
printf '\xEF\xBB\xBF' > "$work/K_bom.txt"; cat "$work/K512.txt" >> "$work/K_bom.txt"
held() { t run --manifest "$work/held.json" --images "$work/w" --output "$work/cal_$tried" "$@"; }
check "held K with skew 150" 2 "held.json: camera.require_calibration: .*/K_skew.txt: K\[0\]\[1\] \(the skew\) is 150" "" -- \
  held --camera-K "$work/K_skew.txt"
check "K with skew 150 (not held)" 0 "K_skew.txt: K\[0\]\[1\] \(the skew\) is 150, not 0" "" -- \
  run_m --images "$work/w" --output "$work/cal_skew" --camera-K "$work/K_skew.txt"
check "K with bottom row 5 7 1" 2 "K_row.txt: the bottom row K\[2\] is '5 7 1', not '0 0 1'" "" -- \
  held --camera-K "$work/K_row.txt"
check "held K with fy = fx / 10" 2 "K_tenth.txt: (fy = 45.99 px is implausible|the aspect ratio)" "" -- \
  held --camera-K "$work/K_tenth.txt"
check "held 1024 px K on 512 px photos" 2 "K1024.txt do not fit the 5 images of 512x342 .*lies [0-9]+ px from their centre" "" -- \
  held --camera-K "$work/K1024.txt"
mkdir -p "$work/mixed_sizes"; cp "$work/w"/000[0-3].jpg "$work/mixed_sizes/"
cp "$root/examples/fountain-P11-small/images/0004.jpg" "$work/mixed_sizes/"
check "mixed sizes: 512 px K, one 1024 px image" 0 "K512.txt: the principal point .* lies [0-9]+ px from the centre of the 1024x683 image '0004.jpg'.*K is not used there" \
  '[ "$(sqlite3 "$work/mixed_out/database.db" "SELECT COUNT(*) FROM tessera_camera_priors WHERE source = '"'user'"'")" = 1 ]' -- \
  run_m --images "$work/mixed_sizes" --output "$work/mixed_out" --camera-K "$work/K512.txt"
check "mixed sizes, held" 2 "K512.txt do not fit the 1024x683 image '0004.jpg'" "" -- \
  t run --manifest "$work/held.json" --images "$work/mixed_sizes" --output "$work/mixed_held" --camera-K "$work/K512.txt"
cp -r "$work/w_out" "$work/map_K"
check "map --camera-K" 0 "re-created the cameras of 5 images as camera 1 \(SIMPLE_RADIAL 512x342, focal 460.4 px, user\)" \
  '[ "$(sqlite3 "$work/map_K/database.db" "SELECT source FROM tessera_camera_priors")" = user ]' -- \
  t map --manifest "$work/m.json" --images "$work/w2" --output "$work/map_K" --camera-K "$work/K512.txt"
check "K file with a UTF-8 BOM" 0 "camera 1: SIMPLE_RADIAL 512x342 focal 460.4 px \(user\)" "" -- \
  run_m --images "$work/w" --output "$work/cal_bom" --camera-K "$work/K_bom.txt"
mkdir -p "$work/K_dir"
check "K is a folder" 2 "K_dir is a folder, not a file" "" -- \
  run_m --images "$work/w" --output "$work/cal_dir" --camera-K "$work/K_dir"
check "fx = 1e-9" 2 "K_tiny.txt: fx = 1e-09 px is implausible for the camera of the 5 images of 512x342" "" -- \
  run_m --images "$work/w" --output "$work/cal_tiny" --camera-K "$work/K_tiny.txt"
check "fx = 1e12" 2 "K_huge.txt: fx = 1e\+12 px is implausible for the camera of the 5 images of 512x342" "" -- \
  run_m --images "$work/w" --output "$work/cal_huge" --camera-K "$work/K_huge.txt"

# Stale results: an image that had no features when its pairs were matched (a crashing
# detector, here its features removed by hand) and is detected again has its pairs
# matched again, and is registered.
subset "$work/stale" 5
t extract --manifest "$work/m.json" --images "$work/stale" --output "$work/stale_out" > /dev/null 2>&1
sqlite3 "$work/stale_out/database.db" "DELETE FROM keypoints WHERE image_id = 5; DELETE FROM descriptors WHERE image_id = 5;
  DELETE FROM tessera_features WHERE image_id = 5" 2> /dev/null
t match --manifest "$work/m.json" --output "$work/stale_out" > /dev/null 2>&1
check "image detected after its pairs were matched" 0 "match: 4 matched pairs were matched from other features" \
  '[ "$(registered "$work/stale_out")" = 5 ]' -- \
  run_m --images "$work/stale" --output "$work/stale_out"

echo
echo "inputs tried: $tried"
echo "crashes: $crashes"
echo "silent wrong outputs: $silent"
echo "unclear messages: $unclear"
echo "other mismatches: $other"
[ $((crashes + silent + unclear + other)) = 0 ]
