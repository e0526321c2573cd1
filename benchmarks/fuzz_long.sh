#!/bin/bash
# A long libFuzzer run of one target (CI runs each for 30 s): builds the clang fuzz
# build in build-fuzz/, replays the regression inputs, then fuzzes. The corpus grows
# in build-fuzz/corpus/TARGET across runs; a finding is written to
# build-fuzz/fuzz-artifacts/ and its path printed. Fix it, then copy the input to
# tests/fuzz/regressions/TARGET/ so that CI replays it.
# usage: benchmarks/fuzz_long.sh TARGET SECONDS
#   TARGET: manifest exif image_header colmap_binary colmap_text ground_truth database
#   e.g. benchmarks/fuzz_long.sh colmap_binary 3600
set -euo pipefail
if [ $# -ne 2 ]; then
  sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
root=$(cd "$(dirname "$0")/.." && pwd)
build=${TESSERA_FUZZ_BUILD_DIR:-$root/build-fuzz}
export TESSERA_FUZZ_CORPUS_DIR=${TESSERA_FUZZ_CORPUS_DIR:-$build/corpus}
export TESSERA_FUZZ_JOBS=1
exec "$root/tests/fuzz/run_fuzzers.sh" "$root" "$build" "$2" "$root/../shared" "$1"
