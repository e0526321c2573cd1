#!/bin/bash
# Sanitizer builds only: the sanitizer run has leak detection on, and it reaches into
# plugins. A detector that allocates and drops 4 KiB per image (failing_detector,
# "fail": "leak") makes `tessera extract` end with AddressSanitizer's exit code 1 and a
# leak report naming the plugin's frame; the same run without the leak exits 0. This fails
# when the run's ASAN_OPTIONS turn leak detection off, and when a plugin's leak is
# reported "from <unknown module>" (plugins unmapped before LeakSanitizer looks).
# usage: leak_sanitizer_test.sh TESSERA FAILING_PLUGIN_DIR SOURCE_DIR
set -uo pipefail
tessera=$1
failing_plugins=$2
source_dir=$3
source "$(dirname "$0")/common.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

mkdir -p "$work/d"
cp "$source_dir/examples/fountain-P11-small/images/0004.jpg" \
   "$source_dir/examples/fountain-P11-small/images/0005.jpg" "$work/d/"
extract() {  # extract FAIL LOG: the exit code of extract with failing_detector
  cat > "$work/m.json" <<JSON
{"pipeline": {"detector": {"plugin": "failing_detector", "options": {"fail": "$1"}}}}
JSON
  rm -rf "$work/out"
  TESSERA_PLUGIN_PATH=$failing_plugins "$tessera" extract --images "$work/d" \
    --output "$work/out" --manifest "$work/m.json" --threads 1 > "$2" 2>&1
  echo $?
}

code=$(extract none "$work/clean.log")
[ "$code" = 0 ] || { cat "$work/clean.log"; fail "without the leak: exit $code, expected 0"; }
grep -q "LeakSanitizer" "$work/clean.log" && { cat "$work/clean.log"; fail "a leak reported without one"; }
echo "without the leak: exit 0, no report"

code=$(extract leak "$work/leak.log")
[ "$code" = 1 ] ||
  { cat "$work/leak.log"; fail "a leaking plugin: exit $code, expected 1 (ASAN_OPTIONS=${ASAN_OPTIONS:-})"; }
grep -q "ERROR: LeakSanitizer: detected memory leaks" "$work/leak.log" ||
  { cat "$work/leak.log"; fail "no LeakSanitizer report"; }
grep -q "Direct leak of 8192 byte(s) in 2 object(s)" "$work/leak.log" ||
  { cat "$work/leak.log"; fail "the report is not the plugin's two blocks of 4 KiB"; }
grep -q "LeakOnPurpose" "$work/leak.log" ||
  { cat "$work/leak.log"; fail "the report does not name the plugin's frame"; }
echo "a leaking plugin: exit 1, its two blocks reported from LeakOnPurpose"
echo PASS
