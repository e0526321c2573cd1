#!/bin/bash
# CI=true turns a skip for missing shared data or colmap into a failure, in the shell
# helpers (tests/end_to_end/common.sh) and the C++ macros (tests/support/skip_or_fail.h).
# Each case runs without CI (a skip, exit 77 or gtest's SKIPPED, with the reason) and with
# CI=true (a failure saying "this test must not skip in CI"). Shared data is made missing
# with TESSERA_SHARED_DIR, colmap with a `colmap` that fails first on the PATH:
#  1. skip_or_fail, require_dataset and skip_part_or_fail themselves;
#  2. interop/colmap_interop_test.sh without the anchors, then without colmap;
#  3. evaluation_test's ReadGroundTruth.StrechaCamerasOfFountain without the shared data;
#  4. database_test's SchemaTextEqualsColmaps without both: a note for each part, then
#     the skip; under CI=true, a failure for each.
# usage: skip_or_fail_test.sh SOURCE_DIR EVALUATION_TEST DATABASE_TEST
set -uo pipefail
source_dir=$1
evaluation_test=$2
database_test=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() {
  echo "FAIL: $*"
  exit 1
}
common="$source_dir/tests/end_to_end/common.sh"
missing="$work/no-shared-data"
mkdir "$work/bin"
printf '#!/bin/sh\nexit 1\n' > "$work/bin/colmap"
chmod +x "$work/bin/colmap"
no_colmap_path="$work/bin:$PATH"
ci_message="this test must not skip in CI"

# expect NAME CODE TEXT COMMAND...: COMMAND exits with CODE and prints TEXT.
expect() {
  local name=$1 code=$2 text=$3
  shift 3
  "$@" > "$work/$name.log" 2>&1
  local got=$?
  [ "$got" = "$code" ] || { cat "$work/$name.log"; fail "$name: exit $got, expected $code"; }
  grep -qF -- "$text" "$work/$name.log" || { cat "$work/$name.log"; fail "$name: no '$text'"; }
  echo "$name: exit $got, '$text'"
}
# local_run / ci_run COMMAND...: without CI, and with CI=true.
local_run() { env -u CI TESSERA_SHARED_DIR="$missing" "$@"; }
ci_run() { env CI=true TESSERA_SHARED_DIR="$missing" "$@"; }

# 1. The shell helpers, each in a script that goes on after it if it can.
script() { echo "source '$common'; $1; echo 'went on'"; }
expect skip_or_fail 77 "SKIP: no data" local_run bash -c "$(script 'skip_or_fail "no data"')"
expect skip_or_fail_ci 1 "FAIL: CI: no data; $ci_message" \
  ci_run bash -c "$(script 'skip_or_fail "no data"')"
expect require_dataset 77 "SKIP: $missing not found" \
  local_run bash -c "$(script "require_dataset '$missing'")"
expect require_dataset_ci 1 "CI: $missing not found; $ci_message" \
  ci_run bash -c "$(script "require_dataset '$missing'")"
expect skip_part 0 "went on" local_run bash -c "$(script 'skip_part_or_fail "one check"')"
grep -qF "SKIPPED (visible): one check" "$work/skip_part.log" || fail "skip_part: no reason"
expect skip_part_ci 1 "CI: one check; $ci_message" \
  ci_run bash -c "$(script 'skip_part_or_fail "one check"')"
# CI means CI=true, nothing else.
expect ci_false 77 "SKIP: no data" env CI=false bash -c "$(script 'skip_or_fail "no data"')"

# 2. A real script: the shared anchors missing, then colmap not running.
interop=("$source_dir/tests/interop/colmap_interop_test.sh" /bin/false /unused)
expect interop_anchors 77 "SKIP: COLMAP's fountain-P11 model not found at $missing" \
  local_run "${interop[@]}"
expect interop_anchors_ci 1 "FAIL: CI: COLMAP's fountain-P11 model not found at $missing" \
  ci_run "${interop[@]}"
mkdir -p "$work/anchors/anchors/colmap-3.8/fountain-P11/sparse/0"
expect interop_colmap 77 "SKIP: colmap is not installed" \
  env -u CI TESSERA_SHARED_DIR="$work/anchors" PATH="$no_colmap_path" "${interop[@]}"
expect interop_colmap_ci 1 "FAIL: CI: colmap is not installed" \
  env CI=true TESSERA_SHARED_DIR="$work/anchors" PATH="$no_colmap_path" "${interop[@]}"

# 3. A C++ test without the shared data.
fountain=(--gtest_filter=ReadGroundTruth.StrechaCamerasOfFountain)
expect gtest_skip 0 "[  SKIPPED ] ReadGroundTruth.StrechaCamerasOfFountain" \
  local_run "$evaluation_test" "${fountain[@]}"
expect gtest_skip_ci 1 "fountain-P11/gt\" not found (set TESSERA_SHARED_DIR); $ci_message" \
  ci_run "$evaluation_test" "${fountain[@]}"
grep -qF "[  FAILED  ] ReadGroundTruth.StrechaCamerasOfFountain" "$work/gtest_skip_ci.log" ||
  fail "gtest_skip_ci: not reported as failed"

# 4. A C++ test with two parts, each needing one of them.
schema=(--gtest_filter=DatabaseTest.SchemaTextEqualsColmaps)
expect gtest_parts 0 "[   NOTE   ] part not run: colmap is not installed" \
  local_run env PATH="$no_colmap_path" "$database_test" "${schema[@]}"
grep -qF "part not run: COLMAP anchor database not found at" "$work/gtest_parts.log" &&
  grep -qF "[  SKIPPED ] DatabaseTest.SchemaTextEqualsColmaps" "$work/gtest_parts.log" ||
  { cat "$work/gtest_parts.log"; fail "gtest_parts: not both notes and the skip"; }
expect gtest_parts_ci 1 "CI: colmap is not installed; its fresh schema is not compared" \
  ci_run env PATH="$no_colmap_path" "$database_test" "${schema[@]}"
grep -qF "CI: COLMAP anchor database not found at" "$work/gtest_parts_ci.log" ||
  fail "gtest_parts_ci: the anchor database's part did not fail"
echo "PASS"
