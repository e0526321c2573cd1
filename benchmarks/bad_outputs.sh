#!/bin/bash
# Tries Tessera's outputs as a hostile user would (issue 32) and counts, for each case:
#   crash                         an exit code other than 0, 2 and 3 where none was due
#   silent wrong output           the expected code, but a wrong, stale or mixed result
#   files outside touched         a file outside the case's output folder changed, added
#                                 or removed (a sentinel tree is checked after each case)
#   foreign files deleted         a file in the output folder that Tessera did not write
#                                 changed or removed
# Issue 47's hand-offs are read as their readers read them: transforms.json's file_path
# joined to the JSON's folder, the 3DGS trainer's camera (check_3dgs_scene.py) on a
# principal point moved off the centre, and the mean error against colmap model_analyzer.
# Every count but the first ("cases tried") must be 0. On a 512 px copy of
# examples/fountain-P11-small with ORB (a few seconds per case).
# usage: benchmarks/bad_outputs.sh [TESSERA]
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
tessera=$(realpath "${1:-$root/build/bin/tessera}")
bin=$(dirname "$tessera")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin/tessera_test_downscale" "$root/examples/fountain-P11-small/images" "$work/all" 512 90 \
  > /dev/null || { echo "downscale failed (build tessera_test_downscale)"; exit 1; }
mkdir -p "$work/d"
for i in 3 4 5 6 7; do cp "$work/all/$(printf %04d "$i").jpg" "$work/d/"; done
manifest() {  # manifest FILE EXPORTERS_JSON [EXTRA_TOP_LEVEL_JSON]
  cat > "$1" <<JSON
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 1500}},
              "pair_selector": ${PAIRS:-{\"plugin\": \"exhaustive\"\}},
              "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": $2},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15}${3:+, $3}}
JSON
}
manifest "$work/bin.json" '[{"plugin": "colmap_binary"}, {"plugin": "ply"}, {"plugin": "transforms_json"}]'
manifest "$work/text.json" '[{"plugin": "colmap_text"}, {"plugin": "transforms_json"}]'
manifest "$work/3dgs.json" '[{"plugin": "colmap_binary"}, {"plugin": "gaussian_splatting"}]'
t() { "$tessera" "$@" --threads 2; }

# The sentinel: files outside every output folder, and a victim for links to point at.
mkdir -p "$work/outside/models/0"
echo "precious" > "$work/outside/victim.txt"
echo "model" > "$work/outside/models/0/images.bin"
snapshot() { (cd "$1" && find . -printf '%y %p\n' | sort && find . -type f | sort | xargs -r sha1sum); }
sentinel=$(snapshot "$work/outside")
tess_base() {  # a finished workspace with a binary model, PLY and transforms.json
  t run --images "$work/d" --output "$work/base" --manifest "$work/bin.json" > "$work/base.log" 2>&1 ||
    { cat "$work/base.log"; echo "the base run failed"; exit 1; }
}
tess_base
fresh() { rm -rf "$1"; cp -a "$work/base" "$1"; }

tried=0 crashes=0 silent=0 outside=0 foreign=0
# check NAME EXPECTED_CODES RESULT_CHECK FOREIGN_FILES -- COMMAND...
#   EXPECTED_CODES: e.g. "2" or "0 3"; RESULT_CHECK: a shell test of the result ("" none);
#   FOREIGN_FILES: files Tessera did not write that must stay as they are ("" none).
check() {
  local name=$1 expected=$2 result_check=$3 foreign_files=$4
  shift 5
  tried=$((tried + 1))
  local sums=""
  for f in $foreign_files; do sums+="$(sha1sum "$f" 2> /dev/null || echo "missing $f")"$'\n'; done
  "$@" > "$work/case.log" 2>&1
  local code=$?
  local verdict=ok
  if ! grep -qw -- "$code" <<< "$expected"; then
    if [ "$code" != 0 ] && [ "$code" != 2 ] && [ "$code" != 3 ]; then
      verdict=crash; crashes=$((crashes + 1))
    else
      verdict="silent wrong output (exit $code, expected $expected)"; silent=$((silent + 1))
    fi
  elif [ -n "$result_check" ] && ! eval "$result_check"; then
    verdict="silent wrong output"; silent=$((silent + 1))
  fi
  if [ "$(snapshot "$work/outside")" != "$sentinel" ]; then
    verdict="files outside touched"; outside=$((outside + 1))
    rm -rf "$work/outside"; mkdir -p "$work/outside/models/0"
    echo "precious" > "$work/outside/victim.txt"; echo "model" > "$work/outside/models/0/images.bin"
  fi
  local after=""
  for f in $foreign_files; do after+="$(sha1sum "$f" 2> /dev/null || echo "missing $f")"$'\n'; done
  if [ "$sums" != "$after" ]; then verdict="foreign files deleted"; foreign=$((foreign + 1)); fi
  printf "%-52s exit %s  %s\n" "$name" "$code" "$verdict"
  [ "$code" = 0 ] || grep -m1 '\[error\]' "$work/case.log" | cut -c1-150 | sed 's/^/    /' 
  [ "$verdict" = ok ] || sed 's/^/    /' "$work/case.log" | grep -v '^\s*\[info\]' | tail -3
}
sums_of() { (cd "$1" && find . -type f ! -name '.tessera_outputs.json' | sort | xargs -r sha1sum); }
# The outputs of a workspace: its models and exports, not its database.
outputs_of() { (cd "$1" && find sparse gaussian_splatting* transforms*.json mapping_summary.json -type f 2> /dev/null | sort | xargs -r sha1sum); }

# --- Data loss --------------------------------------------------------------------------
fresh "$work/p"; mkdir -p "$work/p/sparse/1" "$work/p/sparse/2"
echo notes > "$work/p/sparse/1/notes.txt"; echo theirs > "$work/p/sparse/2/images.bin"
check "COLMAP project's sparse/1 and sparse/2 (map)" 0 "" "$work/p/sparse/1/notes.txt $work/p/sparse/2/images.bin" -- \
  t map --images "$work/d" --output "$work/p" --manifest "$work/bin.json"
check "the same, with run" 0 "" "$work/p/sparse/1/notes.txt $work/p/sparse/2/images.bin" -- \
  t run --images "$work/d" --output "$work/p" --manifest "$work/bin.json"
mkdir -p "$work/q/sparse"; cp -r "$work/d" "$work/q/sparse/3"
check "run --images OUT/sparse/3 --output OUT" 2 '[ ! -e "$work/q/sparse/3/.tessera.lock" ]' "$(ls -d "$work"/q/sparse/3/*)" -- \
  t run --images "$work/q/sparse/3" --output "$work/q" --manifest "$work/bin.json"
fresh "$work/l"; rm -rf "$work/l/sparse"; ln -s "$work/outside/models" "$work/l/sparse"
check "OUTPUT/sparse a link to another folder" 2 "" "" -- \
  t map --images "$work/d" --output "$work/l" --manifest "$work/bin.json"
fresh "$work/g"; g_before=$(sums_of "$work/g/sparse")
check "re-map on a full disk (ulimit -f)" 2 '[ "$(sums_of "$work/g/sparse")" = "$g_before" ] && [ ! -e "$work/g/gaussian_splatting" ]' "" -- \
  bash -c "trap '' XFSZ; ulimit -f 40; exec \"$tessera\" map --images \"$work/d\" --output \"$work/g\" --manifest \"$work/3dgs.json\" --threads 2"
check "rerun after the full disk: no temporaries left" 0 '[ -z "$(cd "$work/g" && find . -name "*.tmp-*" -o -name .tessera_staging)" ]' "" -- \
  t map --images "$work/d" --output "$work/g" --manifest "$work/text.json"
fresh "$work/k"
check "kill -9 between two renames (strace)" 137 '! { ls "$work/k/sparse/0" | grep -q "\.txt$" && ls "$work/k/sparse/0" | grep -q "\.bin$"; }' "" -- \
  strace -f -qq -o /dev/null -e trace=renameat2 -e inject=renameat2:signal=SIGKILL:when=2 \
    "$tessera" map --images "$work/d" --output "$work/k" --manifest "$work/text.json" --threads 2
check "rerun after kill -9: whole, no leftovers" 0 '[ -f "$work/k/sparse/0/images.txt" ] && [ -z "$(cd "$work/k" && find . -name "*.tmp-*" -o -name .tessera_staging -o -name "*.bin")" ]' "" -- \
  t map --images "$work/d" --output "$work/k" --manifest "$work/text.json"
fresh "$work/o"
manifest "$work/db.json" '[{"plugin": "transforms_json", "options": {"file": "database.db"}}]'
check "exporter file database.db" 2 '[ "$(head -c 15 "$work/o/database.db")" = "SQLite format 3" ]' "" -- \
  t map --images "$work/d" --output "$work/o" --manifest "$work/db.json"
manifest "$work/dot.json" '[{"plugin": "colmap_binary"}, {"plugin": "gaussian_splatting", "options": {"folder": "."}}]'
o_before=$(sums_of "$work/o/sparse")
check "exporter folder . beside colmap_binary" 2 '[ "$(sums_of "$work/o/sparse")" = "$o_before" ]' "" -- \
  t map --images "$work/d" --output "$work/o" --manifest "$work/dot.json"
mkdir -p "$work/a"; cp "$work/d"/*.jpg "$work/a/"
check "run --images A --output A (refused)" 2 '[ ! -e "$work/a/.tessera.lock" ] && [ ! -e "$work/a/database.db" ]' "$(ls -d "$work"/a/*)" -- \
  t run --images "$work/a" --output "$work/a" --manifest "$work/bin.json"
fresh "$work/f"
manifest "$work/fail.json" '[{"plugin": "colmap_text"}, {"plugin": "failing_exporter", "options": {"fail": "custom"}}, {"plugin": "gaussian_splatting"}]'
f_before=$(outputs_of "$work/f")
check "a failing exporter mid-set" "1 2" '[ "$(outputs_of "$work/f")" = "$f_before" ]' "" -- \
  env TESSERA_PLUGIN_PATH="$bin/../test_plugins/failing" "$tessera" map --images "$work/d" --output "$work/f" --manifest "$work/fail.json" --threads 2

# --- Security ---------------------------------------------------------------------------
mkdir -p "$work/names/sparse0"
cat > "$work/names/sparse0/cameras.txt" <<'TXT'
1 PINHOLE 512 341 400 400 256 170
TXT
printf '1 1 0 0 0 0 0 0 1 %s\n\n2 1 0 0 0 1 0 0 1 ../../escape.jpg\n\n' "$work/outside/victim.txt" > "$work/names/sparse0/images.txt"
: > "$work/names/sparse0/points3D.txt"
check "3DGS: absolute and ../ image names" 2 '[ ! -e "$work/names/escape.jpg" ]' "" -- \
  "$tessera" export --model "$work/names/sparse0" --format gaussian_splatting --images "$work/d" --output "$work/names/out"
fresh "$work/lock"; rm -f "$work/lock/.tessera.lock"; ln -s "$work/outside/victim.txt" "$work/lock/.tessera.lock"
check ".tessera.lock a link to another file" "0 2" "" "" -- \
  t map --images "$work/d" --output "$work/lock" --manifest "$work/bin.json"
check "Slurm --partition with a newline" 2 '! grep -rqs "^touch pwned" "$work/slurm"' "" -- \
  t slurm --images "$work/d" --output "$work/slurm" --manifest "$work/bin.json" --workers 2 --dry-run --partition $'debug\ntouch pwned'
check "Slurm --sbatch-arg with a newline" 2 '! grep -rqs "^touch pwned" "$work/slurm2"' "" -- \
  t slurm --images "$work/d" --output "$work/slurm2" --manifest "$work/bin.json" --workers 2 --dry-run --sbatch-arg=$'--mem=1G\ntouch pwned'

# --- Silent wrong -----------------------------------------------------------------------
fresh "$work/cam"; cam_before=$(sha1sum < "$work/cam/sparse/0/cameras.bin")
manifest "$work/pinhole.json" '[{"plugin": "colmap_binary"}]'
sed -i 's/"SIMPLE_RADIAL"/"PINHOLE"/' "$work/pinhole.json"
check "camera.model changed on a finished workspace" 0 '[ "$(sha1sum < "$work/cam/sparse/0/cameras.bin")" != "$cam_before" ]' "" -- \
  t run --images "$work/d" --output "$work/cam" --manifest "$work/pinhole.json"
echo "400 0 256 0 400 170 0 0 1" > "$work/K.txt"
check "--camera-K given on a finished workspace" 0 '[ "$(sha1sum < "$work/cam/sparse/0/cameras.bin")" != "$cam_before" ]' "" -- \
  t run --images "$work/d" --output "$work/cam" --manifest "$work/pinhole.json" --camera-K "$work/K.txt"
fresh "$work/s"
check "binary to text: no .bin left" 0 '[ -z "$(find "$work/s" -name "*.bin" -path "*sparse*")" ]' "" -- \
  t map --images "$work/d" --output "$work/s" --manifest "$work/text.json"
check "ply exporter removed: no PLY left" 0 '[ -z "$(find "$work/s" -name "*.ply")" ]' "" -- \
  t map --images "$work/d" --output "$work/s" --manifest "$work/text.json"
fresh "$work/n"; mkdir -p "$work/flat"
python3 "$root/tests/tools/make_test_image.py" flat "$work/flat/a.png"
python3 "$root/tests/tools/make_test_image.py" flat "$work/flat/b.png"
check "exit-3 rerun: no earlier model left" 3 '[ ! -e "$work/n/sparse" ] && python3 -c "import json,sys; assert json.load(open(sys.argv[1]))[\"models\"] == []" "$work/n/mapping_summary.json"' "" -- \
  t run --images "$work/flat" --output "$work/n" --manifest "$work/bin.json"
fresh "$work/pairs"
PAIRS='{"plugin": "window", "options": {"window": 1}}' manifest "$work/window.json" '[{"plugin": "colmap_binary"}]'
check "pair selection narrowed: earlier pairs not mapped" 0 'grep -q "map: 5 images, [1-4] verified pairs" "$work/case.log"' "" -- \
  t run --images "$work/d" --output "$work/pairs" --manifest "$work/window.json"
# A 3DGS re-export of a smaller model (4 of the 5 images): no image of the old one left.
mkdir -p "$work/d4"; cp "$work"/d/000[3456].jpg "$work/d4/"
t run --images "$work/d4" --output "$work/small" --manifest "$work/bin.json" > /dev/null 2>&1
"$tessera" export --model "$work/base/sparse/0" --format gaussian_splatting --images "$work/d" --output "$work/gs" > /dev/null 2>&1
check "3DGS re-export of a smaller model: no old image left" 0 '[ "$(ls "$work/gs/gaussian_splatting/images" | wc -l)" = 4 ] && [ ! -e "$work/gs/gaussian_splatting/images/0007.jpg" ]' "" -- \
  "$tessera" export --model "$work/small/sparse/0" --format gaussian_splatting --images "$work/d4" --output "$work/gs"
# --- Hand-offs read by their readers (issue 47) -----------------------------------------
# file_path joined to the JSON's folder as nerfstudio joins it names the image, byte for byte.
resolves() {
  python3 - "$@" << 'PY'
import filecmp, json, os, sys
images = sys.argv[1]
for frame in json.load(open(sys.argv[2]))["frames"]:
    path = os.path.join(os.path.dirname(sys.argv[2]), frame["file_path"])
    assert filecmp.cmp(path, os.path.join(images, os.path.basename(path)), shallow=False), path
PY
}
check "transforms.json of a run: file_path resolves" 0 'resolves "$work/d" "$work/base/transforms.json"' "" -- true
check "transforms.json export, relative paths" 0 'resolves "$work/d" "$work/tj/transforms.json"' "" -- \
  bash -c "cd '$work' && '$tessera' export --model base/sparse/0 --format transforms_json --images d --output tj"
check "transforms.json export without --images" 2 '[ ! -e "$work/tj2/transforms.json" ]' "" -- \
  "$tessera" export --model "$work/base/sparse/0" --format transforms_json --output "$work/tj2"
# A principal point 7 px off the centre (as bundle adjustment may refine it): the 3DGS
# trainer's camera (principal point at the image centre) must agree with the model's.
"$tessera" export --model "$work/base/sparse/0" --format colmap_text --output "$work/offc" > /dev/null 2>&1
awk '!/^#/ && NF { $6 += 7 } { print }' "$work/offc/sparse/0/cameras.txt" > "$work/offc/cameras.txt" &&
  mv "$work/offc/cameras.txt" "$work/offc/sparse/0/cameras.txt"
check "3DGS export of an off-centre principal point" 0 'python3 "$root/tests/tools/check_3dgs_scene.py" "$work/gs_offc/gaussian_splatting" > /dev/null' "" -- \
  "$tessera" export --model "$work/offc/sparse/0" --format gaussian_splatting --images "$work/d" --output "$work/gs_offc"
# The mean reprojection error is COLMAP's: mapping_summary.json against model_analyzer.
if colmap help > /dev/null 2>&1; then
  check "mean reprojection error = colmap model_analyzer's" 0 'python3 -c "import json,sys; assert abs(json.load(open(sys.argv[1]))[\"models\"][0][\"mean_reprojection_error\"] - float(sys.argv[2])) < 1e-6" "$work/base/mapping_summary.json" "$(sed -n "s/.*Mean reprojection error: \([0-9.]*\)px.*/\1/p" "$work/case.log")"' "" -- \
    colmap model_analyzer --path "$work/base/sparse/0"
fi
check "--threads 65537" 2 "" "" -- \
  "$tessera" run --images "$work/d" --output "$work/thr" --manifest "$work/bin.json" --threads 65537

echo
echo "cases tried: $tried"
echo "crashes: $crashes"
echo "silent wrong outputs: $silent"
echo "files outside the output folder touched: $outside"
echo "files not written by Tessera deleted: $foreign"
[ $((crashes + silent + outside + foreign)) = 0 ]
