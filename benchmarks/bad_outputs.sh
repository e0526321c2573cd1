#!/bin/bash
# Tries Tessera's outputs as a hostile user would (issue 32) and counts, for each case:
#   crash                         an exit code other than 0, 2 and 3 where none was due
#   silent wrong output           the expected code, but a wrong, stale or mixed result
#   files outside touched         a file outside the case's output folder changed, added
#                                 or removed (a sentinel tree is checked after each case)
#   foreign files deleted         a file in the output folder that Tessera did not write
#                                 changed or removed
#   unclear messages              exit 2 or 3 whose last error line (the verdict; a
#                                 multi-process run may print its children's above it)
#                                 names no file, option, image or plugin (no path, quoted
#                                 name or --option in it), or an error the process said
#                                 twice
# and, in the read-back section on clusters.json and the cluster processes (issue 46),
#   models removed by a failed run, orphans after kill -9 of a parent, and cluster
#   processes left 20 s after a signal to their parent.
# Issue 47's hand-offs are read as their readers read them: transforms.json's file_path
# joined to the JSON's folder, the 3DGS trainer's camera (check_3dgs_scene.py) on a
# principal point moved off the centre, and the mean error against colmap model_analyzer.
# The bench children section (issue 60) counts hangs and reports lost too (see there).
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

tried=0 crashes=0 silent=0 outside=0 foreign=0 unclear=0
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
  if [ "$code" = 2 ] || [ "$code" = 3 ]; then
    local verdict_line repeated
    verdict_line=$(grep -E '^\[error\]|^--[a-z-]+: ' "$work/case.log" | tail -1)
    repeated=$(grep '^\[error\]' "$work/case.log" | sort | uniq -d | head -1)
    if ! grep -qE "/|'|--[a-z]" <<< "$verdict_line" || [ -n "$repeated" ]; then
      verdict="unclear message"; unclear=$((unclear + 1))
    fi
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
check "rerun after the full disk: no temporaries left" 0 '[ -z "$(cd "$work/g" && find . -name "*tmp-*" -o -name .tessera_staging)" ]' "" -- \
  t map --images "$work/d" --output "$work/g" --manifest "$work/text.json"
fresh "$work/k"
check "kill -9 between two renames (strace)" 137 '! { ls "$work/k/sparse/0" | grep -q "\.txt$" && ls "$work/k/sparse/0" | grep -q "\.bin$"; }' "" -- \
  strace -f -qq -o /dev/null -e trace=renameat2 -e inject=renameat2:signal=SIGKILL:when=2 \
    "$tessera" map --images "$work/d" --output "$work/k" --manifest "$work/text.json" --threads 2
check "rerun after kill -9: whole, no leftovers" 0 '[ -f "$work/k/sparse/0/images.txt" ] && [ -z "$(cd "$work/k" && find . -name "*tmp-*" -o -name .tessera_staging -o -name "*.bin")" ]' "" -- \
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
# Issue 60: a hard link is not stopped by O_NOFOLLOW (the victim was truncated to 0
# bytes); a file of the user's under the lock's name is not Tessera's either.
fresh "$work/hlock"; rm -f "$work/hlock/.tessera.lock"; ln "$work/outside/victim.txt" "$work/hlock/.tessera.lock"
check ".tessera.lock a hard link to another file" 2 'grep -q "tessera.lock: is a file with 2 names" "$work/case.log"' "" -- \
  t map --images "$work/d" --output "$work/hlock" --manifest "$work/bin.json"
fresh "$work/ulock"; echo "my notes" > "$work/ulock/.tessera.lock"
check ".tessera.lock a file of the user's" 2 "" "$work/ulock/.tessera.lock" -- \
  t map --images "$work/d" --output "$work/ulock" --manifest "$work/bin.json"
# Files named like an interrupted write's temporary, of a process that is gone: the user's.
fresh "$work/tmpn"; echo mine > "$work/tmpn/.notes.tmp-999999"; echo mine > "$work/tmpn/sparse/0/.draft.tmp-999998"
check "user files named .NAME.tmp-PID (map)" 0 "" "$work/tmpn/.notes.tmp-999999 $work/tmpn/sparse/0/.draft.tmp-999998" -- \
  t map --images "$work/d" --output "$work/tmpn" --manifest "$work/bin.json"
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
# Issue 60: a focal length of 0 was exported as 11 black images and fx = 0 (3DGS), and
# "fl_x": 0.0 (transforms.json). Refused by each exporter, naming the camera; nothing placed.
"$tessera" export --model "$work/base/sparse/0" --format colmap_text --output "$work/fx0" > /dev/null 2>&1
awk '!/^#/ && NF { $5 = 0 } { print }' "$work/fx0/sparse/0/cameras.txt" > "$work/fx0/cameras.txt" &&
  mv "$work/fx0/cameras.txt" "$work/fx0/sparse/0/cameras.txt"
for format in gaussian_splatting transforms_json colmap_text colmap_binary; do
  check "focal length 0 exported as $format" 2 'grep -q "camera 1: its focal length f = 0 is not a positive finite number" "$work/case.log" && [ -z "$(cd "$work/fx0_$format" && find . -mindepth 1 ! -path "./.tessera_staging*")" ]' "" -- \
    "$tessera" export --model "$work/fx0/sparse/0" --format "$format" --images "$work/d" --output "$work/fx0_$format"
done
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
# A rig no rig can be (a camera 1e300 m from the reference): refused naming the file and
# the camera, never mapped and reported "given".
mkdir -p "$work/rigimg/left" "$work/rigimg/right"
cp "$work/d/0003.jpg" "$work/d/0004.jpg" "$work/rigimg/left/"
cp "$work/d/0005.jpg" "$work/d/0006.jpg" "$work/rigimg/right/"
cat > "$work/far_rig.json" << 'JSON'
{"cameras": [{"folder": "left", "reference": true},
             {"folder": "right", "cam_from_rig": {"rotation_wxyz": [1, 0, 0, 0],
                                                  "translation": [1e300, 0, 0]}}]}
JSON
check "rig camera 1e300 m from the reference" 2 'grep -q "far_rig.json: .*camera .right." "$work/case.log"' "" -- \
  t run --images "$work/rigimg" --output "$work/rig" --manifest "$work/bin.json" --rig "$work/far_rig.json"
# run_summary.json follows the model set: a map that builds no model (exit 3) leaves none
# that names the models of the run before it.
python3 - "$work/bin.json" "$work/nomodel.json" << 'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["pipeline"]["mapper"] = {"plugin": "incremental", "options": {"init_min_num_inliers": 1000000}}
json.dump(m, open(sys.argv[2], "w"))
PY
fresh "$work/stale"
check "run_summary.json after a map with no model" 3 '[ ! -e "$work/stale/run_summary.json" ] && [ ! -e "$work/stale/sparse" ]' "" -- \
  t map --images "$work/d" --output "$work/stale" --manifest "$work/nomodel.json"
# Python's views of a model are read-only: writing into one raises.
# (the module is built for the Python CMake found: Debian's /usr/bin/python3, with numpy).
build_dir=$(dirname "$(dirname "$tessera")")
pythonpath=$(ls -d "$build_dir"/lib/python3*/dist-packages 2> /dev/null | head -1)
python=$(sed -n 's/^Python3_EXECUTABLE:FILEPATH=//p' "$build_dir/CMakeCache.txt" 2> /dev/null)
if [ -n "$pythonpath" ] && [ -n "$python" ]; then
  check "Python: a model's arrays are read-only" 0 "" "" -- env PYTHONPATH="$pythonpath" "$python" -c "
import tessera, sys
rec = tessera.Reconstruction('$work/base/sparse/0')
point = next(iter(rec.points3D.values()))
assert not point.xyz.flags.writeable
try:
    point.xyz[0] = float('nan')
    sys.exit('a write went through')
except ValueError:
    pass
"
fi
check "--threads 65537" 2 "" "" -- \
  "$tessera" run --images "$work/d" --output "$work/thr" --manifest "$work/bin.json" --threads 65537

# === Read-back: clusters.json and the cluster processes (issue 46) =====================
# A partitioned workspace of the 11 images (clusters of at most 9, 3 shared), mapped by
# map --hierarchical once. Each case works on a copy; counted besides the above:
#   models removed by a failed run   a failing or stopped run changed the merged model
#                                    (sparse/, mapping_summary.json) that was there
#   orphans after kill -9 of a parent  cluster processes running 20 s after a kill -9 of
#                                    the main process of map --hierarchical
#   children left after a signal     the same 20 s after SIGTERM or SIGINT to it alone
removed=0 orphans=0 left_running=0
manifest "$work/part.json" '[{"plugin": "colmap_binary"}]' \
  '"distributed": {"cluster_max_images": 9, "cluster_overlap": 3}'
t run --images "$work/all" --output "$work/cbase" --manifest "$work/part.json" > "$work/cbase.log" 2>&1 &&
  t map --hierarchical --jobs 2 --output "$work/cbase" --manifest "$work/part.json" >> "$work/cbase.log" 2>&1 ||
  { tail -5 "$work/cbase.log"; echo "the partitioned base run failed"; exit 1; }
model_sums() { (cd "$1" && find sparse mapping_summary.json -type f 2> /dev/null | sort | xargs -r sha1sum); }
forge() {  # forge DIR PYTHON: edits DIR/clusters.json, loaded as c
  python3 -c "
import json, sys
c = json.load(open(sys.argv[1]))
$2
json.dump(c, open(sys.argv[1], 'w'))" "$1/clusters.json"
}
# cluster_case NAME EXPECTED MESSAGE FORGE -- COMMAND... (OUT in COMMAND: the case's copy)
cluster_case() {
  local name=$1 expected=$2 message=$3 edit=$4
  shift 5
  local out=$work/c$tried
  rm -rf "$out"; cp -a "$work/cbase" "$out"
  [ -z "$edit" ] || forge "$out" "$edit"
  local before; before=$(model_sums "$out")
  check "$name" "$expected" "grep -qF -- \"${message//OUT/$out}\" \"\$work/case.log\"" "" -- "${@//OUT/$out}"
  # A run that fails (exit other than 0) must leave the model that was there.
  [ "$expected" = 0 ] || [ "$(model_sums "$out")" = "$before" ] ||
    { removed=$((removed + 1)); echo "    the model that was there changed"; }
}
hier=(t map --hierarchical --jobs 2 --output OUT --manifest "$work/part.json")
one=(t map --cluster 0 --output OUT --manifest "$work/part.json")
merge=("$tessera" merge --stage map --output OUT --manifest "$work/part.json")  # no --threads
focal='c["cameras"][0]["focal_length"] = 1e300'
cluster_case "clusters.json focal 1e300 (hierarchical)" 2 "OUT/clusters.json: cameras: camera 1: focal_length 1e+300 px" "$focal" -- "${hier[@]}"
cluster_case "clusters.json focal 1e300 (cluster)" 2 "OUT/clusters.json: cameras: camera 1: focal_length 1e+300 px" "$focal" -- "${one[@]}"
cluster_case "clusters.json focal 1e300 (merge)" 2 "OUT/clusters.json: cameras: camera 1: focal_length 1e+300 px" "$focal" -- "${merge[@]}"
cluster_case "clusters.json focal -1" 2 "OUT/clusters.json: cameras[0].focal_length = -1" 'c["cameras"][0]["focal_length"] = -1' -- "${hier[@]}"
cluster_case "clusters.json focal 0.01 px" 2 "OUT/clusters.json: cameras: camera 1: focal_length 0.01 px" 'c["cameras"][0]["focal_length"] = 0.01' -- "${hier[@]}"
cluster_case "clusters.json focal a string" 2 "OUT/clusters.json: not a clusters file" 'c["cameras"][0]["focal_length"] = "460"' -- "${hier[@]}"
cluster_case "clusters.json camera id 99" 2 "OUT/clusters.json: cameras: camera 99: not a camera of the workspace" 'c["cameras"][0]["camera_id"] = 99' -- "${hier[@]}"
cluster_case "clusters.json camera id 1e300" 2 "OUT/clusters.json: cameras[0].camera_id = 1e+300" 'c["cameras"][0]["camera_id"] = 1e300' -- "${one[@]}"
cluster_case "clusters.json camera listed twice" 2 "OUT/clusters.json: cameras: camera 1 is listed twice" 'c["cameras"].append(c["cameras"][0])' -- "${hier[@]}"
cluster_case "clusters.json image ../../etc/passwd (hierarchical)" 2 "OUT/clusters.json: cluster 0: image '../../etc/passwd' is not an image of the workspace" 'c["clusters"][0]["images"].append("../../etc/passwd")' -- "${hier[@]}"
cluster_case "clusters.json image ../../etc/passwd (cluster)" 2 "OUT/clusters.json: cluster 0: image '../../etc/passwd' is not an image of the workspace" 'c["clusters"][0]["images"].append("../../etc/passwd")' -- "${one[@]}"
cluster_case "clusters.json image /etc/passwd in a core" 2 "OUT/clusters.json: cluster 1: image '/etc/passwd' is not an image of the workspace" 'c["clusters"][1]["images"].append("/etc/passwd"); c["clusters"][1]["core"].append("/etc/passwd")' -- "${merge[@]}"
cluster_case "clusters.json isolated image not in workspace" 2 "OUT/clusters.json: isolated: image 'ghost.jpg' is not an image of the workspace" 'c["isolated"].append("ghost.jpg")' -- "${hier[@]}"
cluster_case "clusters.json image listed twice" 2 "OUT/clusters.json: cluster 0: images: image '" 'c["clusters"][0]["images"].append(c["clusters"][0]["images"][0])' -- "${hier[@]}"
cluster_case "clusters.json image in two cores" 2 "is in the core of cluster 0 too" 'x = c["clusters"][0]["core"][0]; c["clusters"][1]["core"].append(x); c["clusters"][1]["images"] = sorted(set(c["clusters"][1]["images"] + [x]))' -- "${one[@]}"
cluster_case "clusters.json image dropped from every core" 2 "has verified pairs but is in no cluster's core" 'x = c["clusters"][0]["core"].pop(); [k["images"].remove(x) for k in c["clusters"] if x in k["images"]]; [n["shared"].remove(x) for k in c["clusters"] for n in k["neighbours"] if x in n["shared"]]' -- "${hier[@]}"
cluster_case "clusters.json neighbour 99" 2 "OUT/clusters.json: cluster 0: neighbour 99: not another cluster" 'c["clusters"][0]["neighbours"].append({"cluster": 99, "shared": []})' -- "${hier[@]}"
cluster_case "clusters.json cluster missing from the tree" 2 "is missing from its list or its tree" 'c["tree"] = {"cluster": 0}' -- "${hier[@]}"
cluster_case "clusters.json tree 100000 levels deep" 2 "tree: deeper than 1000 levels" 'text = json.dumps(c).replace(json.dumps(c["tree"]), "{\"children\": [" * 100000 + "{\"cluster\": 0}" + "]}" * 100000)
open(sys.argv[1], "w").write(text); sys.exit(0)' -- "${hier[@]}"
cluster_case "clusters.json not JSON (not partitioned over)" 2 "OUT/clusters.json: not a clusters file" 'open(sys.argv[1], "w").write("{not json"); sys.exit(0)' -- "${hier[@]}"
cluster_case "clusters.json missing (stale: partitioned again)" 0 "map: partitioning again" "" -- bash -c 'rm "$0/clusters.json"; exec "$@"' OUT "${hier[@]/#t/$tessera}"
# The advice works: the merge's command maps a truncated cluster again, then the merge.
out=$work/advice; rm -rf "$out"; cp -a "$work/cbase" "$out"
truncate -s 100 "$out/clusters/1/sparse/0/points3D.bin"
check "truncated cluster: merge names a command" 2 'grep -q "run \`tessera map --cluster 1 " "$work/case.log"' "" -- "${merge[@]//OUT/$out}"
advice=$(grep -o 'run `tessera map --cluster 1 [^`]*`' "$work/case.log" | head -1 | sed 's/^run `tessera //; s/`$//')
# shellcheck disable=SC2086
check "truncated cluster: the command it names" 0 'grep -q "moved aside to" "$work/case.log"' "" -- "$tessera" $advice --threads 2
check "truncated cluster: the merge after it" 0 'grep -q "merge: .* into 1 model(s), 11 of 11 images" "$work/case.log"' "" -- "${merge[@]//OUT/$out}"
manifest "$work/partfail.json" '[{"plugin": "colmap_binary"}]' \
  '"distributed": {"cluster_max_images": 9, "cluster_overlap": 3}'
sed -i 's/"bundle_adjuster"/"mapper": {"plugin": "failing_mapper"}, "bundle_adjuster"/' "$work/partfail.json"
cluster_case "every cluster fails (failing_mapper)" 3 "map --hierarchical: no cluster of OUT holds a model" "" -- \
  env TESSERA_PLUGIN_PATH="$bin/../test_plugins/failing" "$tessera" map --hierarchical --jobs 2 --threads 1 --output OUT --manifest "$work/partfail.json"

# Signals to the main process of map --hierarchical alone, and kill -9 of it, once a
# cluster process runs (one at a time, the clusters not mapped yet).
alive() { [ -r "/proc/$1/status" ] && ! grep -q '^State:[[:space:]]*Z' "/proc/$1/status"; }
# parent_case NAME SIGNAL EXPECTED [stop]: "stop" stops the cluster processes first, as a
# cluster busy in a long step is: only a death signal ends them then.
parent_case() {
  local name=$1 signal=$2 expected=$3 stop=${4:-} out=$work/sig$tried
  tried=$((tried + 1))
  rm -rf "$out"; cp -a "$work/cbase" "$out"; rm -rf "$out/clusters"
  local before; before=$(model_sums "$out")
  "$tessera" map --hierarchical --jobs 1 --threads 1 --output "$out" --manifest "$work/part.json" > "$work/case.log" 2>&1 &
  local pid=$! kids="" deadline=$((SECONDS + 60))
  while [ -z "$kids" ] && [ "$SECONDS" -lt "$deadline" ] && kill -0 "$pid" 2> /dev/null; do
    kids=$(pgrep -P "$pid"); sleep 0.05
  done
  # shellcheck disable=SC2086
  [ -z "$stop" ] || kill -STOP $kids 2> /dev/null
  kill -"$signal" "$pid"; wait "$pid" 2> /dev/null; local code=$?
  deadline=$((SECONDS + 20))
  local left=0 kid
  for kid in $kids; do while alive "$kid" && [ "$SECONDS" -lt "$deadline" ]; do sleep 0.1; done; done
  for kid in $kids; do alive "$kid" && { left=$((left + 1)); kill -9 "$kid"; }; done
  local verdict=ok
  if [ -z "$kids" ]; then verdict="no cluster process seen"; silent=$((silent + 1))
  elif [ "$left" != 0 ]; then
    verdict="$left cluster process(es) left after 20 s"
    if [ "$signal" = KILL ]; then orphans=$((orphans + left)); else left_running=$((left_running + left)); fi
  elif [ "$code" != "$expected" ]; then verdict="exit $code, expected $expected"; silent=$((silent + 1))
  elif grep -q "merge: " "$work/case.log"; then verdict="merged after the signal"; silent=$((silent + 1))
  fi
  [ "$(model_sums "$out")" = "$before" ] || { removed=$((removed + 1)); verdict="model removed"; }
  printf "%-52s exit %s  %s\n" "$name" "$code" "$verdict"
}
parent_case "SIGTERM to the main process alone" TERM 130
parent_case "SIGINT to the main process alone" INT 130
parent_case "kill -9 of the main process" KILL 137
parent_case "kill -9 of the main process, children stopped" KILL 137 stop
# === End of the read-back section on clusters.json and cluster processes ===============
# --- Read-back: forged ledgers (issue 46) ------------------------------------------------
# OUTPUT/.tessera_outputs.json edited as a forger would: each entry below carries the real
# size and XXH3 of the file it names. Tessera must refuse the ledger (exit 2, naming it and
# the entry) and delete nothing. Kept in one function so that other read-back sections
# (clusters.json, signals) sit beside it.
forge() {  # forge OUTPUT ENTRY [FILE]: ENTRY added with FILE's size and XXH3; no FILE: a folder
  python3 - "$@" <<'PY'
import ctypes, ctypes.util, json, os, sys
out, entry = sys.argv[1], sys.argv[2]
path = os.path.join(out, ".tessera_outputs.json")
ledger = json.load(open(path))
if len(sys.argv) > 3:
    data = open(sys.argv[3], "rb").read()
    xxhash = ctypes.CDLL(ctypes.util.find_library("xxhash"))
    xxhash.XXH3_64bits.restype = ctypes.c_uint64
    xxhash.XXH3_64bits.argtypes = [ctypes.c_char_p, ctypes.c_size_t]
    ledger["files"].append({"path": entry, "size": len(data),
                            "xxh3": "%016x" % xxhash.XXH3_64bits(data, len(data))})
else:
    ledger["folders"].append(entry)
json.dump(ledger, open(path, "w"), indent=1)
PY
}
readback_forged_ledgers() {
  local o before named
  # forged NAME ENTRY FILE KEEP [VERB] [CHECK]: a fresh workspace with ENTRY forged for
  # FILE (none: a folder entry); then VERB (map) must exit 2 naming the ledger and the
  # entry, with the outputs, the files KEEP and what CHECK tests as they were.
  forged() {
    local name=$1 entry=$2 file=$3 keep=$4 verb=${5:-map} also=${6:-true}
    o="$work/forged"; fresh "$o"
    forge "$o" "$entry" ${file:+"$file"}
    before=$(outputs_of "$o")
    named="grep -qF \"tessera_outputs.json: the entry '$entry'\" \"\$work/case.log\""
    local images=""; [ "$verb" = run ] && images="--images $work/d"
    check "forged ledger: $name ($verb)" 2 "$named"' && [ "$(outputs_of "$o")" = "$before" ] && '"$also" \
      "$keep" -- t $verb $images --output "$o" --manifest "$work/bin.json"
  }
  forged "../victim.txt" "../outside/victim.txt" "$work/outside/victim.txt" ""
  forged "../victim.txt" "../outside/victim.txt" "$work/outside/victim.txt" "" run
  forged "an absolute path" "$work/outside/victim.txt" "$work/outside/victim.txt" ""
  forged "sparse/0/../../../x" "sparse/0/../../../outside/victim.txt" "$work/outside/victim.txt" ""
  forged "database.db" "database.db" "$work/forged/database.db" "$work/forged/database.db"
  forged "an input image" "../d/0003.jpg" "$work/d/0003.jpg" "$work/d/0003.jpg"
  forged "an input image (absolute)" "$work/d/0004.jpg" "$work/d/0004.jpg" "$work/d/0004.jpg"
  # ORB and brute_force cache nothing: a search index as flann leaves it stands for one.
  mkdir -p "$work/base/cache/matcher/flann"; echo index > "$work/base/cache/matcher/flann/1.idx"
  forged "a file under cache/" "cache/matcher/flann/1.idx" "$work/base/cache/matcher/flann/1.idx" \
    "$work/forged/cache/matcher/flann/1.idx"
  # The images inside OUTPUT, given with --images: an entry naming one, with its digest,
  # passes the checks of the path, but an input is never removed: left, with a warning.
  o="$work/forged"; fresh "$o"; cp -r "$work/d" "$o/photos"
  forge "$o" "photos/0003.jpg" "$o/photos/0003.jpg"; forge "$o" "photos"
  check "forged ledger: an input image inside OUTPUT (map)" 0 'grep -q "photos/0003.jpg is left as it is: .tessera_outputs.json records it as Tessera.s, but it is, holds or lies in the input folder" "$work/case.log"' \
    "$o/photos/0003.jpg" -- t map --images "$o/photos" --output "$o" --manifest "$work/bin.json"
  mkdir -p "$work/empty_folder"
  forged "an empty folder outside (folders)" "../empty_folder" "" "" map '[ -d "$work/empty_folder" ]'
  forged "the ledger itself" ".tessera_outputs.json" "$work/base/.tessera_outputs.json" ""
  # Issue 60: a ledger naming a folder of the user's: its files named like temporaries
  # (.x.tmp-N, N a process that is gone) were emptied as "left by an interrupted write".
  o="$work/forged"; fresh "$o"; mkdir -p "$o/photos"
  echo mine > "$o/photos/.x.tmp-999997"; echo mine > "$o/photos/.y.tmp-999996"
  forge "$o" "photos"
  check "forged ledger: a user folder's .x.tmp-N files" 0 "" "$o/photos/.x.tmp-999997 $o/photos/.y.tmp-999996" -- \
    t map --images "$work/d" --output "$o" --manifest "$work/bin.json"
  # OUTPUT/sparse moved away and replaced by a link to it: every recorded digest matches
  # through the link, and nothing may be removed or replaced through it.
  o="$work/forged"; fresh "$o"; rm -rf "$work/moved_sparse"; mv "$o/sparse" "$work/moved_sparse"
  ln -s "$work/moved_sparse" "$o/sparse"
  local moved; moved=$(sums_of "$work/moved_sparse")
  check "ledger entries through a link (OUTPUT/sparse)" 2 'grep -q "a symbolic link" "$work/case.log" && [ "$(sums_of "$work/moved_sparse")" = "$moved" ]' "" -- \
    t map --output "$o" --manifest "$work/bin.json"
  # A file Tessera wrote, edited since: named as that, not as "not in the ledger".
  o="$work/forged"; fresh "$o"; echo '{"edited": true}' > "$o/transforms.json"
  check "an edited output is told from a foreign one" 2 'grep -q "Tessera wrote but that has changed since" "$work/case.log" && ! grep -q "not in .tessera_outputs.json" "$work/case.log"' "$o/transforms.json" -- \
    t map --output "$o" --manifest "$work/bin.json"
}
readback_forged_ledgers
# --- End of read-back: forged ledgers ---------------------------------------------------
# --- Bench children (issue 60) -------------------------------------------------------------
# `tessera bench` with hostile COLMAP binaries (fake ones, shell scripts written here) beside
# one Tessera row, and signals to the bench while a COLMAP step runs. Beside the counts above
# (a crash: an exit code other than expected; files outside: the sentinel tree, which a
# version "3.8/../../../../outside/pwn" aims at), each case counts:
#   hangs            the bench still running 120 s after it began (or 20 s after a signal)
#   reports lost     a bench that ran rows and printed no table, or wrote no JSON, or lost
#                    the Tessera row (its row, exit 0, its workspace's database)
#   unclear          the expected line not said, an error line of 1000 characters or more,
#                    raw control bytes in the log, or an interrupt reported as a crash
hangs=0 lost=0
bench_children() {
  local bc=$work/bc
  mkdir -p "$bc"
  fake() {  # fake NAME HELP EXTRACT MAPPER: a COLMAP running those shell lines
    cat > "$bc/$1" <<SH
#!/bin/bash
args=("\$@")
get() { local i; for ((i = 0; i < \${#args[@]}; i++)); do [ "\${args[i]}" = "\$1" ] && echo "\${args[i+1]}"; done; }
db=\$(get --database_path); out=\$(get --output_path)
case "\$1" in
  -h) $2 ;;
  feature_extractor) $3 ;;
  exhaustive_matcher) : ;;
  mapper|global_mapper) $4 ;;
esac
SH
    chmod +x "$bc/$1"
  }
  local help='echo "COLMAP 3.8 -- Structure-from-Motion"; echo "  mapper"'
  local copy_db="cp '$work/base/database.db' \"\$db\""
  local sleeper="echo \$\$ > '$bc/sleep.pid'; exec sleep 600"
  fake good "$help" "$copy_db" ":"
  fake long_version 'printf "COLMAP 3.8"; head -c 30000 /dev/zero | tr "\\0" x; echo' "$copy_db" ":"
  fake dotdot 'echo "COLMAP 3.8/../../../../outside/pwn"' "$copy_db" ":"
  fake silent 'exec sleep 600' "$copy_db" ":"
  fake slow_extract "$help" "$sleeper" ":"
  fake huge 'head -c 100000000 /dev/zero | tr "\\0" x' "$copy_db" ":"
  fake binary 'head -c 3000 /dev/urandom; printf "\\001\\033[31m\\377"' "$copy_db" ":"
  fake garbage_db "$help" "head -c 5000 /dev/urandom > \"\$db\"" ":"
  fake garbage_model "$help" "$copy_db" 'mkdir -p "$out/0"; for f in cameras images points3D; do head -c 300 /dev/urandom > "$out/0/$f.bin"; done'
  fake removes_output "$help" "$copy_db" 'rm -rf "$out"'
  fake crashes "$help" "$copy_db" 'kill -SEGV $$'
  # bench_child NAME EXPECTED_CODE REPORT MESSAGE FOREIGN -- BENCH ARGS...: REPORT "rows"
  # when the bench runs rows (then the table, the JSON and the Tessera row must be there);
  # MESSAGE a regex the log must hold ("" none); FOREIGN files of the user's that must stay.
  bench_child() {
    local name=$1 expected=$2 report=$3 message=$4 foreign_files=$5
    shift 6
    tried=$((tried + 1))
    local out=$bc/case$tried sums="" after="" f verdict=ok
    rm -rf "$out"; mkdir -p "$out"
    for f in $foreign_files; do sums+="$(sha1sum "$f" 2>&1)"; done
    timeout 120 "$tessera" bench --images "$work/d" --output "$out/out" --threads 2 \
      --json "$out/report.json" "$@" > "$out/table.md" 2> "$out/log"
    local code=$?
    if [ "$code" = 124 ]; then verdict=hang; hangs=$((hangs + 1))
    elif [ "$code" != "$expected" ] && [ "$code" != 0 ] && [ "$code" != 2 ] && [ "$code" != 3 ]; then
      verdict="crash"; crashes=$((crashes + 1))
    elif [ "$code" != "$expected" ]; then verdict="silent wrong output (exit $code)"; silent=$((silent + 1))
    elif [ "$report" = rows ] && { ! grep -q "^| bin |" "$out/table.md" || ! python3 - "$out/report.json" <<'PY'
import json, os, sys
rows = json.load(open(sys.argv[1]))["rows"]
tessera = [r for r in rows if not r["plugins"].startswith("COLMAP")]
assert tessera and all(r["exit_code"] == 0 and os.path.exists(r["workspace"] + "/database.db")
                       for r in tessera), rows
PY
    }; then verdict="report lost"; lost=$((lost + 1))
    elif { [ -n "$message" ] && ! grep -qE -- "$message" "$out/log"; } || [ "$(wc -L < "$out/log")" -ge 1000 ] ||
         LC_ALL=C grep -qP '[^\t\x20-\x7e]' "$out/log"; then
      verdict="unclear message"; unclear=$((unclear + 1))
    fi
    if [ "$(snapshot "$work/outside")" != "$sentinel" ]; then
      verdict="files outside touched"; outside=$((outside + 1))
      rm -rf "$work/outside"; mkdir -p "$work/outside/models/0"
      echo "precious" > "$work/outside/victim.txt"; echo "model" > "$work/outside/models/0/images.bin"
    fi
    for f in $foreign_files; do after+="$(sha1sum "$f" 2>&1)"; done
    [ "$sums" = "$after" ] || { verdict="foreign files deleted"; foreign=$((foreign + 1)); }
    printf "%-52s exit %s  %s\n" "bench children: $name" "$code" "$verdict"
    [ "$code" = 0 ] || grep -m1 '\[error\]' "$out/log" | cut -c1-150 | sed 's/^/    /'
    [ "$verdict" = ok ] || tail -c 600 "$out/log" | tail -3 | cut -c1-300 | sed 's/^/    /'
  }
  local long="long_version" bin_json="$work/bin.json"
  bench_child "30,000-character version line" 0 rows "" "" -- --colmap "$bc/$long" "$bin_json"
  bench_child "version 3.8/../../../../outside/pwn" 0 rows "colmap-3.8_.._.._.._.._outside_pwn-incremental" "" -- --colmap "$bc/dotdot" "$bin_json"
  bench_child "silent on -h (--child-timeout 3)" 2 none "silent: no answer to -h \(its version\) within 3 s" "" -- \
    --child-timeout 3 --colmap "$bc/silent" "$bin_json"
  bench_child "sleeping in feature_extractor (--child-timeout 3)" 2 rows "timed out after 3 s" "" -- \
    --child-timeout 3 --colmap "$bc/slow_extract" "$bin_json"
  tried=$((tried + 1))
  if [ -s "$bc/sleep.pid" ] && kill -0 "$(cat "$bc/sleep.pid")" 2> /dev/null; then
    echo "    the timed-out COLMAP still runs"; hangs=$((hangs + 1)); kill -9 "$(cat "$bc/sleep.pid")"
  else printf "%-52s %s\n" "bench children: the timed-out COLMAP is gone" ok; fi
  bench_child "100 MB on one line from -h" 2 none "huge: does not say it is COLMAP" "" -- --colmap "$bc/huge" "$bin_json"
  bench_child "binary output from -h" 2 none "binary: does not say it is COLMAP \(its -h begins '.*\\\\x" "" -- --colmap "$bc/binary" "$bin_json"
  bench_child "garbage database" 2 rows "colmap-3.8-incremental ended with exit code 2: .*database.db" "" -- --colmap "$bc/garbage_db" "$bin_json"
  bench_child "garbage model" 2 rows "colmap-3.8-incremental ended with exit code 2: .*\.bin" "" -- --colmap "$bc/garbage_model" "$bin_json"
  bench_child "a mapper that removes its output" 2 rows "output folder is gone" "" -- --colmap "$bc/removes_output" "$bin_json"
  bench_child "a mapper that crashes" 2 rows "mapper crashed \(signal 11\)" "" -- --colmap "$bc/crashes" "$bin_json"
  cp "$work/bin.json" "$bc/colmap-3.8-incremental.json"
  bench_child "manifest named colmap-3.8-incremental.json" 0 rows "" "" -- --colmap "$bc/good" "$bin_json" "$bc/colmap-3.8-incremental.json"
  bench_child "--colmap X --colmap X" 0 rows "" "" -- --colmap "$bc/good" --colmap "$bc/good" "$bin_json"
  python3 -c 'import json, sys; names = [r["manifest"] for r in json.load(open(sys.argv[1]))["rows"]]
assert len(set(names)) == len(names) == 3, names' "$bc/case$tried/report.json" 2> /dev/null ||
    { echo "    two rows of one name"; silent=$((silent + 1)); }
  mkdir -p "$bc/user/out/colmap/colmap-3.8/incremental"; echo mine > "$bc/user/out/colmap/colmap-3.8/incremental/notes.txt"
  echo mine > "$bc/user/out/notes.txt"
  check "bench children: a user's folder where a COLMAP row goes" 2 "" "$bc/user/out/notes.txt $bc/user/out/colmap/colmap-3.8/incremental/notes.txt" -- \
    "$tessera" bench --images "$work/d" --output "$bc/user/out" --threads 2 --colmap "$bc/good" "$bin_json"
  # Signals while COLMAP sleeps in feature_extractor: to the bench alone, and to its group.
  local signal target
  for signal in INT TERM INT:group; do
    tried=$((tried + 1))
    rm -f "$bc/sleep.pid"; rm -rf "$bc/sig"
    setsid "$tessera" bench --images "$work/d" --output "$bc/sig" --threads 2 --colmap "$bc/slow_extract" \
      "$bin_json" > "$bc/sig.md" 2> "$bc/sig.log" &
    local pid=$! deadline=$((SECONDS + 120))
    while [ ! -s "$bc/sleep.pid" ] && [ "$SECONDS" -lt "$deadline" ]; do sleep 0.1; done
    target=$pid; [ "${signal#*:}" = group ] && target=-$pid
    kill -"${signal%%:*}" -- "$target"
    deadline=$((SECONDS + 20))
    while kill -0 "$pid" 2> /dev/null && [ "$SECONDS" -lt "$deadline" ]; do sleep 0.1; done
    local verdict=ok code
    if kill -0 "$pid" 2> /dev/null; then
      verdict=hang; hangs=$((hangs + 1)); kill -9 "$pid"
    fi
    wait "$pid"; code=$?
    if [ "$verdict" = ok ] && [ "$code" != 130 ]; then verdict="crash (exit $code)"; crashes=$((crashes + 1)); fi
    if [ "$verdict" = ok ] && { ! grep -q "bench: interrupted" "$bc/sig.log" || grep -q crashed "$bc/sig.log"; }; then
      verdict="unclear message"; unclear=$((unclear + 1))
    fi
    if [ "$verdict" = ok ] && ! grep -q "^| bin |" "$bc/sig.md"; then verdict="report lost"; lost=$((lost + 1)); fi
    if [ -s "$bc/sleep.pid" ] && kill -0 "$(cat "$bc/sleep.pid")" 2> /dev/null; then
      verdict="COLMAP left running"; hangs=$((hangs + 1)); kill -9 "$(cat "$bc/sleep.pid")"
    fi
    printf "%-52s exit %s  %s\n" "bench children: SIG${signal%%:*} to the bench$([ "${signal#*:}" = group ] && echo "'s group" || echo " alone")" "$code" "$verdict"
    [ "$verdict" = ok ] || tail -3 "$bc/sig.log" | sed 's/^/    /'
  done
}
bench_children
# --- End of bench children -----------------------------------------------------------------

echo
echo "cases tried: $tried"
echo "crashes: $crashes"
echo "silent wrong outputs: $silent"
echo "files outside the output folder touched: $outside"
echo "files not written by Tessera deleted: $foreign"
echo "unclear messages: $unclear"
echo "models removed by a failed run: $removed"
echo "orphans after kill -9 of a parent: $orphans"
echo "cluster processes left 20 s after a signal to their parent: $left_running"
echo "hangs (bench children): $hangs"
echo "reports lost (bench children): $lost"
[ $((crashes + silent + outside + foreign + unclear + removed + orphans + left_running + hangs + lost)) = 0 ]
