#!/bin/bash
# The plugin as built (issue 50): on small copies of the sample,
# - a detector that crashed twice on an image is quarantined there (the summary counts
#   the image), and once rebuilt (another file hash) it runs on it again, the log saying
#   that the crash records of the older build were set aside, without a file deleted by
#   hand; `tessera plugins --forget-crashes` forgets the records;
# - a plugin on TESSERA_PLUGIN_PATH named like a bundled one is named in the run log
#   with the file it shadows, and run_summary.json records the file that ran;
# - a map without a model points at "the warnings above" only when there are some;
# - a bundle adjuster that asks the host for itself is exit 2 naming the chain.
# All of it from an installed prefix, as a plugin author meets it: BUILD_DIR is installed
# into a temporary prefix, whose tessera and bundled plugins are the ones run.
# usage: plugin_builds_test.sh BUILD_DIR DOWNSCALE SOURCE_DIR TEST_PLUGIN_ROOT
set -uo pipefail
build_dir=$1
downscale=$2
source_dir=$3
test_plugins=$4
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cmake --install "$build_dir" --prefix "$work/prefix" > "$work/install.log" ||
  { cat "$work/install.log"; fail "install into a prefix"; }
tessera="$work/prefix/bin/tessera"
bundled="$work/prefix/lib/tessera/plugins"
[ -x "$tessera" ] && [ -f "$bundled/libtessera_detector_orb.so" ] || fail "the prefix lacks tessera or orb"

images="$source_dir/examples/fountain-P11-small/images"
"$downscale" "$images" "$work/big" 512 90 > /dev/null || fail "downscale"
"$downscale" "$images" "$work/small" 384 90 > /dev/null || fail "downscale"
mkdir -p "$work/d" "$work/plugins"
for i in 3 4 5; do cp "$work/big/$(printf %04d "$i").jpg" "$work/d/"; done
cp "$work/small/0006.jpg" "$work/d/"
width=384  # the sample is landscape: its longer side, the width, is downscaled to 384
cp "$test_plugins/failing/libtessera_test_failing_detector.so" "$work/plugins/"
cat > "$work/crash.json" <<JSON
{"pipeline": {"detector": {"plugin": "failing_detector", "options": {"fail": "segv", "on_width": $width}}}}
JSON
extract() {  # extract LOG: the exit code of extract with the crashing detector
  TESSERA_PLUGIN_PATH="$work/plugins" "$tessera" extract --images "$work/d" --output "$work/out" \
    --manifest "$work/crash.json" --threads 1 > "$1" 2>&1
  echo $?
}

# Two crashes on 0006.jpg, then it is skipped, and the summary counts it.
for k in 1 2; do
  code=$(extract "$work/x$k.log")
  [ "$code" = 4 ] || { cat "$work/x$k.log"; fail "crash $k: exit $code, expected 4"; }
done
code=$(extract "$work/x3.log")
[ "$code" = 0 ] || { cat "$work/x3.log"; fail "quarantined: exit $code, expected 0"; }
grep -q "skipping 0006.jpg: it crashed detector 'failing_detector' twice" "$work/x3.log" ||
  { cat "$work/x3.log"; fail "quarantined: not said"; }
grep -q ", 1 skipped by quarantine," "$work/x3.log" ||
  { cat "$work/x3.log"; fail "the summary does not count the quarantined image"; }
echo "crashed twice on 0006.jpg, then skipped, and counted in the summary"

# Rebuilt: the same plugin with another file hash runs on the image again.
printf 'rebuilt' >> "$work/plugins/libtessera_test_failing_detector.so"
code=$(extract "$work/x4.log")
[ "$code" = 4 ] || { cat "$work/x4.log"; fail "rebuilt: exit $code, expected 4 (run again)"; }
grep -q "plugin 'failing_detector': 2 crash records of an older build (version 1.0.0, file [0-9a-f]*, options [0-9a-f]*) were set aside" "$work/x4.log" ||
  { cat "$work/x4.log"; fail "rebuilt: the records set aside were not said"; }
grep -q "crashed (SIGSEGV) while detecting image 0006.jpg" "$work/x4.log" ||
  { cat "$work/x4.log"; fail "rebuilt: it did not run on 0006.jpg again"; }
[ "$(wc -l < "$work/out/plugin_crashes.tsv")" = 2 ] || fail "the crash history lost a record"
echo "rebuilt: the older build's records set aside, the plugin run again"

# Forgotten: the records go, and the run reports no older build.
"$tessera" plugins --forget-crashes "$work/out" > "$work/forget.log" 2>&1 ||
  { cat "$work/forget.log"; fail "--forget-crashes"; }
grep -q "Forgot 3 plugin crash record(s) in $work/out" "$work/forget.log" ||
  { cat "$work/forget.log"; fail "--forget-crashes: count"; }
[ ! -e "$work/out/plugin_crashes.tsv" ] && [ ! -e "$work/out/plugin_crashes.new" ] ||
  fail "--forget-crashes left a record"
code=$(extract "$work/x5.log")
[ "$code" = 4 ] && ! grep -q "set aside" "$work/x5.log" && ! grep -q "previous run ended in a crash" "$work/x5.log" ||
  { cat "$work/x5.log"; fail "after --forget-crashes: exit $code"; }
echo "--forget-crashes: every record forgotten"

# Shadowing: a copy of the bundled orb on TESSERA_PLUGIN_PATH.
mkdir -p "$work/shadow"
cp "$bundled/libtessera_detector_orb.so" "$work/shadow/libmy_orb.so"
cat > "$work/orb.json" <<JSON
{"pipeline": {"detector": {"plugin": "orb", "options": {"max_num_features": 500}},
              "pair_selector": {"plugin": "exhaustive"}, "matcher": {"plugin": "brute_force"},
              "bundle_adjuster": {"plugin": "ceres"}, "exporters": [{"plugin": "colmap_text"}]},
 "camera": {"model": "SIMPLE_RADIAL", "single_camera": true}}
JSON
mkdir -p "$work/three"
for i in 3 4 5; do cp "$work/big/$(printf %04d "$i").jpg" "$work/three/"; done
TESSERA_PLUGIN_PATH="$work/shadow" "$tessera" run --images "$work/three" --output "$work/shadowed" \
  --manifest "$work/orb.json" > "$work/shadow.log" 2>&1
code=$?
[ "$code" = 0 ] || [ "$code" = 3 ] || { cat "$work/shadow.log"; fail "shadowed run: exit $code"; }
grep -q "\[warning\] pipeline.detector: plugin 'orb' runs from $work/shadow/libmy_orb.so (version [^)]*); it shadows .*/libtessera_detector_orb.so (version [^)]*), found later on the plugin path" "$work/shadow.log" ||
  { cat "$work/shadow.log"; fail "the shadowing plugin was not named with the file it shadows"; }
if [ "$code" = 0 ]; then
  python3 - "$work/shadowed/run_summary.json" "$work/shadow/libmy_orb.so" <<'PY' || fail "run_summary.json: the file that ran"
import json, sys
used = {p["slot"]: p for p in json.load(open(sys.argv[1]))["plugins"]}
assert used["detector"]["file"] == sys.argv[2], used["detector"]
assert len(used["detector"]["file_hash"]) == 16, used["detector"]
PY
fi
echo "shadowing: both files named in the run log, the file that ran in run_summary.json"

# No model: the verdict points at "the warnings above" only when some were logged.
sed 's|"bundle_adjuster"|"mapper": {"plugin": "failing_mapper"}, "bundle_adjuster"|' "$work/orb.json" > "$work/nomodel.json"
TESSERA_PLUGIN_PATH="$test_plugins/failing" "$tessera" map --output "$work/shadowed" \
  --manifest "$work/nomodel.json" > "$work/nomodel.log" 2>&1
code=$?
[ "$code" = 3 ] || { cat "$work/nomodel.log"; fail "a mapper that maps nothing: exit $code, expected 3"; }
if grep -q "\[warning\]" "$work/nomodel.log"; then
  grep -q "initialised a model (see the warnings above)" "$work/nomodel.log"
else
  ! grep -q "see the warnings above" "$work/nomodel.log" &&
    grep -q "no pair of images initialised a model$" "$work/nomodel.log"
fi || { cat "$work/nomodel.log"; fail "the no-model verdict and the warnings above disagree"; }
grep -q "\[warning\]" "$work/nomodel.log" || echo "(no warning was logged: the verdict points at none)"
echo "no model: the verdict points at warnings only when there are some"

# A bundle adjuster that asks the host for itself: exit 2 naming the chain.
cat > "$work/self.json" <<JSON
{"pipeline": {"detector": {"plugin": "orb"}, "pair_selector": {"plugin": "exhaustive"},
              "matcher": {"plugin": "brute_force"},
              "bundle_adjuster": {"plugin": "wrapping_a", "options": {"wrap": "wrapping_a"}},
              "exporters": [{"plugin": "colmap_text"}]}}
JSON
TESSERA_PLUGIN_PATH="$test_plugins/wrapping" "$tessera" run --images "$work/three" \
  --output "$work/self" --manifest "$work/self.json" > "$work/self.log" 2>&1
code=$?
[ "$code" = 2 ] || { cat "$work/self.log"; fail "self-wrapping plugin: exit $code, expected 2"; }
grep -q "\[error\] $work/self.json: pipeline.bundle_adjuster: plugin creation loops: 'wrapping_a' -> 'wrapping_a': plugin 'wrapping_a' asks the host for the bundle_adjuster 'wrapping_a'" "$work/self.log" ||
  { cat "$work/self.log"; fail "self-wrapping plugin: the chain was not named"; }
echo "self-wrapping plugin: exit 2 naming the chain"
echo "PASS"
