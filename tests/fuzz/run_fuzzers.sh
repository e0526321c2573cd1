#!/bin/bash
# Builds the libFuzzer targets with clang in their own build folder, replays every
# regression input under regressions/<target>/, then fuzzes each target for a bounded
# time from seeds made from real files. Fails on any crash, leak, timeout or
# non-InputError exception and prints the reproducer's path.
#
# Usage: run_fuzzers.sh SOURCE_DIR BUILD_DIR [SECONDS] [SHARED_DIR] [TARGET...]
#   SECONDS     per target (default 30); 0 replays the regression inputs only.
#   SHARED_DIR  folder with datasets/ for more seeds (optional; TESSERA_SHARED_DIR replaces
#               it; its absence is a failure under CI=true, where it is always there).
#   TARGET      manifest exif image_header colmap_binary colmap_text ground_truth database
#               (default: all).
# Environment: TESSERA_FUZZ_CORPUS_DIR keeps the corpus there between runs (default: a
# temporary copy); TESSERA_FUZZ_JOBS targets run at once (default 2).
# Exit codes: 0 no finding, 1 a finding or a build failure, 77 clang's fuzzer runtime
# is missing (skipped; under CI=true a failure, as scripts/install_dependencies.sh
# installs it: common.sh's skip_or_fail).
set -euo pipefail

source_dir=$(cd "$1" && pwd)
build_dir=$2
seconds=${3:-30}
shared_dir=${TESSERA_SHARED_DIR:-${4:-}}
shift $(($# < 4 ? $# : 4))
source "$source_dir/tests/end_to_end/common.sh"
all_targets=(manifest exif image_header colmap_binary colmap_text ground_truth database)
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=("${all_targets[@]}")
jobs=${TESSERA_FUZZ_JOBS:-2}

work=$(mktemp -d "${TMPDIR:-/tmp}/tessera_fuzz_run.XXXXXX")
trap 'rm -rf "$work"' EXIT

# --- clang and its libFuzzer runtime -------------------------------------------------
clangxx=${TESSERA_FUZZ_CXX:-$(command -v clang++ || true)}
if [ -z "$clangxx" ]; then
  skip_or_fail "run_fuzzers: clang++ not found (Debian package clang)"
fi
printf '#include <cstddef>\n#include <cstdint>\nextern "C" int LLVMFuzzerTestOneInput(const uint8_t*, size_t) { return 0; }\n' \
  > "$work/probe.cc"
if ! "$clangxx" -fsanitize=fuzzer,address,undefined "$work/probe.cc" -o "$work/probe" \
     > "$work/probe.log" 2>&1; then
  head -3 "$work/probe.log"
  skip_or_fail "run_fuzzers: $clangxx cannot link -fsanitize=fuzzer (libFuzzer's runtime," \
               "Debian package libclang-rt-dev, is missing)"
fi

# --- build ------------------------------------------------------------------------------
launcher=()
if command -v ccache > /dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  # Share the cache between build folders and checkouts (debug info keeps the first
  # folder's name, which only symbolisation reads).
  export CCACHE_BASEDIR=$source_dir CCACHE_NOHASHDIR=1
fi
start=$(date +%s)
# -O1 and line tables only: quick to build, assertions kept, stacks with file:line.
cmake -S "$source_dir" -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
      -DCMAKE_CXX_COMPILER="$clangxx" -DTESSERA_FUZZ=ON -DTESSERA_BUILD_TESTS=OFF \
      -DTESSERA_BUILD_BENCHMARKS=OFF "${launcher[@]}" > "$work/configure.log" 2>&1 ||
  { cat "$work/configure.log"; exit 1; }
build_targets=(tessera_make_fuzz_seeds)
for target in "${targets[@]}"; do build_targets+=("tessera_fuzz_$target"); done
nice -n 10 cmake --build "$build_dir" -j2 --target "${build_targets[@]}" > "$work/build.log" 2>&1 ||
  { tail -40 "$work/build.log"; exit 1; }
echo "run_fuzzers: built ${#targets[@]} fuzz targets in $(($(date +%s) - start)) s"
bin=$build_dir/bin

# --- regression inputs: each must run cleanly -------------------------------------------
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
failed=0
for target in "${targets[@]}"; do
  regressions=$source_dir/tests/fuzz/regressions/$target
  [ -d "$regressions" ] || continue
  mapfile -t inputs < <(find "$regressions" -type f | sort)
  [ ${#inputs[@]} -gt 0 ] || continue
  if "$bin/tessera_fuzz_$target" -runs=1 "${inputs[@]}" > "$work/regressions_$target.log" 2>&1; then
    echo "run_fuzzers: $target: ${#inputs[@]} regression inputs pass"
  else
    echo "run_fuzzers: FAILED: $target fails on a regression input under $regressions:"
    tail -30 "$work/regressions_$target.log"
    failed=1
  fi
done
[ "$failed" = 0 ] || exit 1
[ "$seconds" != 0 ] || exit 0

# --- seeds from real files ----------------------------------------------------------------
seeds=$work/seeds
example_images=("$source_dir"/examples/fountain-P11-small/images/*.jpg)
"$bin/tessera_make_fuzz_seeds" "$seeds" "${example_images[0]}"
mkdir -p "$seeds"/{manifest,exif,image_header,ground_truth}
cp "$source_dir"/manifests/*.json "$seeds/manifest/"
# The sample JPEGs' headers (up to the start of the scan) with a little image data and
# the end-of-image marker, so that the scan accepts them.
for image in "${example_images[@]:0:3}"; do
  name=$(basename "$image" .jpg)
  head -c 4096 "$image" > "$seeds/exif/sample_$name"
  { head -c 1024 "$image"; printf '\xff\xd9'; } > "$seeds/image_header/sample_$name.jpg"
done
# Ground truth: the first byte picks the reader (0 .camera, 1 transforms.json, 2 K.txt).
add_ground_truth_seed() {  # SELECTOR FILE NAME
  { printf "\\x0$1"; cat "$2"; } > "$seeds/ground_truth/$3"
}
add_ground_truth_seed 2 "$source_dir/examples/fountain-P11-small/K.txt" K_fountain_small
datasets=${shared_dir:+$shared_dir/datasets}
if [ -n "$datasets" ] && [ -d "$datasets" ]; then
  for set in "$datasets"/*/; do
    name=$(basename "$set")
    if [ -f "$set/K.txt" ]; then add_ground_truth_seed 2 "$set/K.txt" "K_$name"; fi
    if [ -f "$set/transforms.json" ]; then
      add_ground_truth_seed 1 "$set/transforms.json" "transforms_$name"
    fi
    for camera in $(find "$set" -maxdepth 2 -name '*.camera' | sort | head -2); do
      add_ground_truth_seed 0 "$camera" "camera_${name}_$(basename "$camera")"
    done
    # A JPEG with EXIF (sceaux-castle's camera writes it): its APP1 segment as a seed.
    first_image=$(find "$set/images" -maxdepth 1 -iname '*.jpg' 2> /dev/null | sort | head -1)
    if [ -n "$first_image" ]; then head -c 16384 "$first_image" > "$seeds/exif/dataset_$name"; fi
  done
else
  skip_part_or_fail "run_fuzzers: no shared datasets at '${datasets:-}': ground-truth seeds" \
    "from the committed ones only"
fi
for target in "${targets[@]}"; do
  for extra in seeds regressions; do
    if [ -d "$source_dir/tests/fuzz/$extra/$target" ]; then
      cp "$source_dir/tests/fuzz/$extra/$target"/* "$seeds/$target/"
    fi
  done
done

# --- fuzzing ------------------------------------------------------------------------------
corpus_root=${TESSERA_FUZZ_CORPUS_DIR:-$work/corpus}
artifacts=${TESSERA_FUZZ_ARTIFACT_DIR:-$build_dir/fuzz-artifacts}
mkdir -p "$artifacts"
run_target() {  # TARGET
  local target=$1
  local corpus=$corpus_root/$target
  local rc=0
  mkdir -p "$corpus"
  "$bin/tessera_fuzz_$target" "$corpus" "$seeds/$target" -max_total_time="$seconds" \
    -timeout=10 -rss_limit_mb=2048 -max_len=131072 -print_final_stats=1 \
    -artifact_prefix="$artifacts/$target-" > "$work/fuzz_$target.log" 2>&1 || rc=$?
  echo "$rc" > "$work/rc_$target"
}
for target in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
  run_target "$target" &
done
wait
for target in "${targets[@]}"; do
  log=$work/fuzz_$target.log
  if [ "$(cat "$work/rc_$target")" = 0 ]; then
    execs=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | grep -o '[0-9]*$' || echo "?")
    echo "run_fuzzers: $target: no finding in ${seconds} s ($execs runs, coverage $cov)"
  else
    echo "run_fuzzers: FAILED: $target found a problem; reproduce with"
    echo "  $bin/tessera_fuzz_$target $(grep -o "Test unit written to .*" "$log" | sed 's/Test unit written to //' | head -1)"
    grep -E "ERROR:|runtime error|tessera fuzz:|SUMMARY" "$log" | head -5 || true
    tail -40 "$log"
    failed=1
  fi
done
exit "$failed"
