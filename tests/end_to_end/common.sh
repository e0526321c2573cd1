# Shared by the end-to-end and interoperability scripts (sourced): failing, skipping for
# missing shared data or colmap (a failure in CI), the dataset check and the scores of a
# model by `tessera eval`. The scripts take the shared data folder (../shared) as an
# argument; TESSERA_SHARED_DIR, when set, replaces it.

fail() {
  echo "FAIL: $*"
  exit 1
}

# CI=true: set by GitHub Actions, GitLab CI and most others, and by hand to try it. The
# shared data and colmap are always there in CI, so a skip for their absence would hide a
# broken path.
in_ci() { [ "${CI:-}" = true ]; }

# skip_or_fail REASON: CTest's skip (exit 77) with the reason, or exit 1 in CI. Only for
# missing shared data or colmap; what a machine may lack for good (a display, Slurm,
# Open3D) skips with a plain `echo "SKIP: reason"; exit 77`.
skip_or_fail() {
  if in_ci; then
    echo "FAIL: CI: $*; this test must not skip in CI"
    exit 1
  fi
  echo "SKIP: $*"
  exit 77
}

# skip_part_or_fail REASON: for one check that cannot run while the rest of the test can:
# a line saying so, or exit 1 in CI.
skip_part_or_fail() {
  if in_ci; then
    echo "FAIL: CI: $*; this test must not skip in CI"
    exit 1
  fi
  echo "SKIPPED (visible): $*"
}

# wait_until_paused PID: returns once PID has stopped itself at the place that
# TESSERA_TEST_PAUSE names (util/test_pause.h); fails if it ends first. The test then acts
# at a known point in the run (kill -9, SIGINT, a second writer) and resumes it with
# `kill -CONT`, instead of racing a timer against the process.
wait_until_paused() {
  local state
  while kill -0 "$1" 2> /dev/null; do
    state=$(awk '{print $3}' "/proc/$1/stat" 2> /dev/null)
    [ "$state" = T ] && return 0
    sleep 0.02
  done
  fail "process $1 ended before it paused where TESSERA_TEST_PAUSE asked"
}

# True when colmap runs (not merely when a file of that name is on the PATH).
have_colmap() { colmap help > /dev/null 2>&1; }

# Skips (skip_or_fail) when DATASET has no images folder.
require_dataset() {
  [ -d "$1/images" ] || skip_or_fail "$1 not found"
}

# TESSERA MODEL GT: prints "registered pos_mean_rel mean_reprojection_error_px".
model_scores() {
  "$1" eval "$2" "$3" --json | python3 -c '
import json, sys
e = json.load(sys.stdin)
print(e["registered"], e["pos_mean_rel"], e["mean_reprojection_error_px"])'
}

# The start of a test on geotagged copies of fountain-P11 (georeference, spatial,
# gps_outlier): takes the scripts' arguments TESSERA DOWNSCALE GEOTAG SHARED_DIR
# SOURCE_DIR and sets tessera, downscale, geotag, shared, source_dir, dataset (skipping
# without it or its ground truth) and work, a folder removed on exit.
start_fountain_gps_test() {
  tessera=$1
  downscale=$2
  geotag=$3
  shared=${TESSERA_SHARED_DIR:-$4}
  source_dir=$5
  dataset="$shared/datasets/fountain-P11"
  require_dataset "$dataset"
  [ -d "$dataset/gt" ] || skip_or_fail "$dataset/gt not found"
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
}
