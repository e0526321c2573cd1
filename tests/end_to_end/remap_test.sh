#!/bin/bash
# An unchanged map is kept (issue 51). On a 512 px copy of 6 images of the sample
# examples/fountain-P11-small (in the repository), with ORB for speed:
#  1. `run` again, then `map`, with the same inputs: the model is kept (its files and
#     mapping_summary.json byte for byte, "kept" logged and in run_summary.json, no
#     mapper line); --force-map maps again, to the same model;
#  2. a mapper option changed maps again, naming the mapper; so does a matcher option
#     (the matches), naming the matches;
#  3. a model edited by hand maps again (the edit is then refused as changed since,
#     exit 2); removed, it maps again and is placed;
#  4. a map killed (kill -9) at each rename that places its set: the rerun maps again.
# usage: remap_test.sh TESSERA DOWNSCALE SOURCE_DIR
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
manifest() {  # manifest FILE MAPPER_OPTIONS RATIO
  cat > "$1" <<JSON
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 1500}},
              "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "brute_force", "options": {"ratio": $3, "cross_check": true}},
              "mapper": {"plugin": "incremental", "options": $2},
              "bundle_adjuster": {"plugin": "ceres"},
              "exporters": [{"plugin": "colmap_binary"}]},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15}}
JSON
}
manifest "$work/m.json" '{}' 0.8
manifest "$work/mapper.json" '{"max_reg_trials": 4}' 0.8
manifest "$work/matcher.json" '{}' 0.79
tess() {  # tess LOG MANIFEST VERB ARGS...: VERB on the workspace, exit 0 expected
  local log=$1 manifest=$2 verb=$3
  shift 3
  "$tessera" "$verb" --output "$work/out" --manifest "$manifest" --threads 2 "$@" > "$log" 2>&1 ||
    { tail -30 "$log"; fail "$verb $* ($log)"; }
}
mapper_line="images registered in [0-9]* model(s) by the incremental mapper"
kept() {  # kept LOG: the model was kept, the mapper not run
  grep -q "map: inputs unchanged since .*; kept the 1 model(s) in $work/out (pass --force-map" "$1" ||
    { cat "$1"; fail "$1: the model was not kept"; }
  if grep -q "$mapper_line\|map: registered " "$1"; then cat "$1"; fail "$1: kept, yet the mapper ran"; fi
}
mapped() {  # mapped LOG [REASON]: the mapper ran, for REASON when given
  grep -q "$mapper_line" "$1" || { cat "$1"; fail "$1: the mapper did not run"; }
  if grep -q "kept the" "$1"; then cat "$1"; fail "$1: mapped, yet said kept"; fi
  [ $# -lt 2 ] || grep -qF -- "$2" "$1" || { cat "$1"; fail "$1: no line with '$2'"; }
}
model() { (cd "$1" && sha1sum sparse/0/* mapping_summary.json); }
sparse() { (cd "$1" && sha1sum sparse/0/*); }

# 1. Unchanged: kept by run and by map; --force-map maps again.
tess "$work/1.log" "$work/m.json" run --images "$work/images"
mapped "$work/1.log"
grep -q '"kept": false' "$work/out/run_summary.json" || fail "run_summary.json: no \"kept\": false"
before=$(model "$work/out")
tess "$work/2.log" "$work/m.json" run --images "$work/images"
kept "$work/2.log"
[ "$(model "$work/out")" = "$before" ] || fail "run again: the kept model's files changed"
grep -q '"kept": true' "$work/out/run_summary.json" || fail "run_summary.json: no \"kept\": true"
grep -q "run: model 0 (sparse/0) holds 6 of 6 images" "$work/2.log" ||
  { cat "$work/2.log"; fail "run again: the kept model's images are not said"; }
tess "$work/3.log" "$work/m.json" map
kept "$work/3.log"
[ "$(model "$work/out")" = "$before" ] || fail "map again: the kept model's files changed"
tess "$work/4.log" "$work/m.json" map --force-map
mapped "$work/4.log"
[ "$(sparse "$work/out")" = "$(echo "$before" | grep sparse/)" ] ||
  fail "--force-map: not the same model"
echo "unchanged: kept by run and by map, byte for byte; --force-map maps again"

# 2. A mapper option, then a matcher option.
tess "$work/5.log" "$work/mapper.json" map
mapped "$work/5.log" "map: the mapper, its options or the seed changed since the model of"
tess "$work/6.log" "$work/mapper.json" map
kept "$work/6.log"
tess "$work/7.log" "$work/matcher.json" run --images "$work/images"
mapped "$work/7.log" "the matches, their verification or the selected pairs"
tess "$work/8.log" "$work/m.json" run --images "$work/images"
mapped "$work/8.log" "map: the matches, their verification or the selected pairs changed"
[ "$(sparse "$work/out")" = "$(echo "$before" | grep sparse/)" ] ||
  fail "back to the first manifest: not the first model"
echo "a mapper option, a matcher option: mapped again, naming what changed"

# 3. A model edited by hand, then removed.
printf 'edit' >> "$work/out/sparse/0/points3D.bin"
"$tessera" map --output "$work/out" --manifest "$work/m.json" --threads 2 > "$work/9.log" 2>&1
code=$?
[ "$code" = 2 ] || { cat "$work/9.log"; fail "an edited model: exit $code, expected 2"; }
grep -q "sparse/0/points3D.bin was changed after Tessera wrote it; mapping again" "$work/9.log" &&
  grep -q "map: model 0: 6 images" "$work/9.log" || { cat "$work/9.log"; fail "an edited model: not mapped again"; }
grep -q "points3D.bin.* that Tessera wrote but that has changed since" "$work/9.log" ||
  { cat "$work/9.log"; fail "an edited model: the edit was not refused by name"; }
rm "$work/out/sparse/0/points3D.bin"
tess "$work/10.log" "$work/m.json" map
mapped "$work/10.log" "sparse/0/points3D.bin is missing; mapping again"
[ "$(sparse "$work/out")" = "$(echo "$before" | grep sparse/)" ] ||
  fail "a removed model file: not the first model"
echo "an edited model: mapped again, the edit refused by name; removed: mapped again"

# 4. kill -9 at each rename that places the set of a changed map (strace fault injection).
cp -a "$work/out" "$work/base"
killed=0
for n in 1 2 3 4 5 6 7 8; do
  rm -rf "$work/out" && cp -a "$work/base" "$work/out"
  strace -f -qq -e trace=renameat2 -e inject=renameat2:signal=SIGKILL:when=$n -o /dev/null \
    "$tessera" map --output "$work/out" --manifest "$work/mapper.json" --threads 2 \
    > "$work/k$n.log" 2>&1
  code=$?
  [ "$code" = 137 ] || [ "$code" = 9 ] || break
  killed=$((killed + 1))
  tess "$work/k$n-rerun.log" "$work/mapper.json" map
  mapped "$work/k$n-rerun.log"
  tess "$work/k$n-again.log" "$work/mapper.json" map
  kept "$work/k$n-again.log"
done
if [ "$killed" -gt 0 ]; then
  echo "kill -9 at each of the $killed renames placing the set: the rerun maps again"
else
  cat "$work/k1.log"
  skip_part_or_fail "strace could not inject a kill (exit $code)"
fi
echo "PASS"
