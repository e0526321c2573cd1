#!/bin/bash
# Crash quarantine beyond detectors and matchers (issue 28, item 3; the mapper, issue 24),
# on a 512 px copy of
# the sample (5 images, ORB): a pair selector or a bundle adjuster that crashes is named (exit 4), reported by the
# next run, and refused with its name once it has crashed twice on the same bundle
# (exit 2), the workspace kept; an exporter that crashes twice on a model is skipped for
# it, with a warning and a line in mapping_summary.json, and the other exporters' set is
# placed.
# usage: quarantine_test.sh TESSERA DOWNSCALE SOURCE_DIR FAILING_PLUGIN_DIR
set -uo pipefail
tessera=$1
downscale=$2
source_dir=$3
export TESSERA_PLUGIN_PATH=$4
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$downscale" "$source_dir/examples/fountain-P11-small/images" "$work/all" 512 90 > /dev/null ||
  fail "downscale"
mkdir -p "$work/d"
for i in 3 4 5 6 7; do cp "$work/all/$(printf %04d "$i").jpg" "$work/d/"; done
manifest() {  # manifest FILE BUNDLE_ADJUSTER_JSON EXPORTERS_JSON
  cat > "$1" <<JSON
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 1500}},
              "pair_selector": ${PAIRS:-{\"plugin\": \"exhaustive\"\}},
              "matcher": {"plugin": "brute_force", "options": {"ratio": 0.8, "cross_check": true}},
              "bundle_adjuster": $2,
              "exporters": $3},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true},
 "verification": {"max_error_px": 4.0, "min_num_inliers": 15}}
JSON
}
manifest "$work/ba.json" '{"plugin": "failing_bundle_adjuster", "options": {"fail": "segv"}}' '[{"plugin": "colmap_binary"}]'
PAIRS='{"plugin": "failing_pair_selector", "options": {"fail": "segv"}}' \
  manifest "$work/ps.json" '{"plugin": "ceres"}' '[{"plugin": "colmap_binary"}]'
manifest "$work/ex.json" '{"plugin": "ceres"}' '[{"plugin": "failing_exporter", "options": {"fail": "segv"}}, {"plugin": "colmap_text"}]'
tess() {  # tess LOG MANIFEST VERB ARGS...
  local log=$1 file=$2
  shift 2
  "$tessera" "$@" --manifest "$file" --threads 2 > "$log" 2>&1
}

# A bundle adjuster that crashes: exit 4 twice, then refused by name; matches kept.
tess "$work/b1.log" "$work/ba.json" run --images "$work/d" --output "$work/b"
code=$?
[ "$code" = 4 ] || { cat "$work/b1.log"; fail "bundle adjuster crash: exit $code, expected 4"; }
grep -q "\[error\] plugin 'failing_bundle_adjuster' crashed (SIGSEGV) while adjusting a bundle of" "$work/b1.log" ||
  { cat "$work/b1.log"; fail "bundle adjuster crash: not named"; }
tess "$work/b2.log" "$work/ba.json" map --images "$work/d" --output "$work/b"
code=$?
[ "$code" = 4 ] || { cat "$work/b2.log"; fail "second bundle adjuster crash: exit $code, expected 4"; }
grep -q "the previous run ended in a crash: plugin 'failing_bundle_adjuster'" "$work/b2.log" ||
  { cat "$work/b2.log"; fail "the crash was not reported by the next run"; }
tess "$work/b3.log" "$work/ba.json" map --images "$work/d" --output "$work/b"
code=$?
[ "$code" = 2 ] || { cat "$work/b3.log"; fail "quarantined bundle adjuster: exit $code, expected 2"; }
grep -q "(2 crashes there: 'failing_bundle_adjuster' is refused on a bundle of .* from now on; choose another plugin)" "$work/b3.log" ||
  { cat "$work/b3.log"; fail "the quarantine was not announced"; }
grep -q "\[error\] bundle adjuster 'failing_bundle_adjuster' crashed twice on a bundle of .* choose another pipeline.bundle_adjuster" "$work/b3.log" ||
  { cat "$work/b3.log"; fail "quarantined bundle adjuster: message"; }
[ "$(sqlite3 "$work/b/database.db" 'SELECT COUNT(*) FROM two_view_geometries WHERE rows > 0')" -gt 0 ] ||
  fail "the verified matches were lost"
echo "bundle adjuster: named at each crash, refused by name after two, the matches kept"

# A pair selector that crashes: exit 4 twice, then refused by name; features kept.
for k in 1 2; do
  tess "$work/p$k.log" "$work/ps.json" run --images "$work/d" --output "$work/p"
  code=$?
  [ "$code" = 4 ] || { cat "$work/p$k.log"; fail "pair selector crash $k: exit $code, expected 4"; }
done
tess "$work/p3.log" "$work/ps.json" run --images "$work/d" --output "$work/p"
code=$?
[ "$code" = 2 ] || { cat "$work/p3.log"; fail "quarantined pair selector: exit $code, expected 2"; }
grep -q "\[error\] pipeline.pair_selector: pair selector 'failing_pair_selector' crashed twice selecting pairs among 5 images" "$work/p3.log" ||
  { cat "$work/p3.log"; fail "quarantined pair selector: message"; }
[ "$(sqlite3 "$work/p/database.db" 'SELECT COUNT(*) FROM keypoints')" = 5 ] || fail "the features were lost"
echo "pair selector: named at each crash, refused by name after two, the features kept"

# An exporter that crashes: skipped for the model after two crashes, the rest placed.
tess "$work/e1.log" "$work/ex.json" run --images "$work/d" --output "$work/e"
[ "$?" = 4 ] || { cat "$work/e1.log"; fail "exporter crash: expected exit 4"; }
tess "$work/e2.log" "$work/ex.json" map --images "$work/d" --output "$work/e"
[ "$?" = 4 ] || { cat "$work/e2.log"; fail "second exporter crash: expected exit 4"; }
tess "$work/e3.log" "$work/ex.json" map --images "$work/d" --output "$work/e" ||
  { cat "$work/e3.log"; fail "quarantined exporter: the map failed"; }
grep -q "\[warning\] map: exporter 'failing_exporter' skipped for model 0: it crashed twice" "$work/e3.log" ||
  { cat "$work/e3.log"; fail "quarantined exporter: no warning"; }
[ -f "$work/e/sparse/0/images.txt" ] || fail "quarantined exporter: the other exporter's model is missing"
python3 -c 'import json,sys; q=json.load(open(sys.argv[1]))["quarantined"]; assert len(q) == 1 and "failing_exporter" in q[0], q' \
  "$work/e/mapping_summary.json" || fail "quarantined exporter: not in mapping_summary.json"
echo "exporter: skipped for the model after two crashes, listed in the summary, the rest placed"

# A mapper that crashes: exit 4 naming it, then refused by name; the model of an earlier
# run with the bundled mapper stays, and the incremental mapper maps the same workspace.
mapper_manifest() {  # mapper_manifest FILE MAPPER_JSON
  sed "s|\"bundle_adjuster\": {\"plugin\": \"ceres\"}|\"mapper\": $2, \"bundle_adjuster\": {\"plugin\": \"ceres\"}|" \
    "$work/ex.json" | sed 's|\[{"plugin": "failing_exporter", "options": {"fail": "segv"}}, |[|' > "$1"
}
mapper_manifest "$work/ma.json" '{"plugin": "failing_mapper", "options": {"fail": "segv"}}'
mapper_manifest "$work/mb.json" '{"plugin": "failing_mapper", "options": {"fail": "bad_result"}}'
mapper_manifest "$work/mi.json" '{"plugin": "incremental"}'
tess "$work/m0.log" "$work/mi.json" run --images "$work/d" --output "$work/m" ||
  { cat "$work/m0.log"; fail "incremental mapper run"; }
before=$(sha256sum < "$work/m/sparse/0/images.txt")
cp -a "$work/m" "$work/n"  # for the bad result, away from the crashes' quarantine
for k in 1 2; do
  tess "$work/m$k.log" "$work/ma.json" map --images "$work/d" --output "$work/m"
  code=$?
  [ "$code" = 4 ] || { cat "$work/m$k.log"; fail "mapper crash $k: exit $code, expected 4"; }
done
grep -q "\[error\] plugin 'failing_mapper' crashed (SIGSEGV) while mapping 5 images" "$work/m1.log" ||
  { cat "$work/m1.log"; fail "mapper crash: not named"; }
tess "$work/m3.log" "$work/ma.json" map --images "$work/d" --output "$work/m"
code=$?
[ "$code" = 2 ] || { cat "$work/m3.log"; fail "quarantined mapper: exit $code, expected 2"; }
grep -q "\[error\] pipeline.mapper: mapper 'failing_mapper' crashed twice mapping 5 images" "$work/m3.log" ||
  { cat "$work/m3.log"; fail "quarantined mapper: message"; }
tess "$work/m4.log" "$work/mb.json" map --images "$work/d" --output "$work/n"
code=$?
[ "$code" = 1 ] || { cat "$work/m4.log"; fail "a mapper's bad result: exit $code, expected 1"; }
grep -q "plugin 'failing_mapper' failed while mapping: it returned model 0 where image .* comes back with another id, name or camera" "$work/m4.log" ||
  { cat "$work/m4.log"; fail "a mapper's bad result: message"; }
for ws in m n; do
  [ "$before" = "$(sha256sum < "$work/$ws/sparse/0/images.txt")" ] || fail "the earlier model in $ws was touched"
done
[ ! -e "$work/outside.jpg" ] || fail "a file was written outside the workspace"
tess "$work/m5.log" "$work/mi.json" map --images "$work/d" --output "$work/m" ||
  { cat "$work/m5.log"; fail "the incremental mapper after the failing one"; }
echo "mapper: named at each crash, refused by name after two, a bad result refused, the model kept"
echo "PASS"
