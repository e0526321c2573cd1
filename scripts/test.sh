#!/bin/bash
# Runs the whole test suite: installs missing packages (idempotently), builds with
# warnings as errors, runs every test, then runs the unit tests again under
# AddressSanitizer and UndefinedBehaviorSanitizer, with LeakSanitizer on.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install_dependencies.sh
jobs=$(nproc)
source scripts/compiler_cache.sh

# The quickstart's options (its objects are reused through ccache), with the tests, the
# benchmarks and the Python module.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DTESSERA_WERROR=ON -DTESSERA_BUILD_TESTS=ON \
      -DTESSERA_BUILD_BENCHMARKS=ON -DTESSERA_BUILD_PYTHON=ON "${launcher[@]}" > /dev/null
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs"

if [ "${TESSERA_SKIP_SANITIZERS:-0}" != "1" ]; then
  # -O1 and line tables (-g1), as AddressSanitizer's guide advises: reports still name the
  # file and line, and the instrumented code compiles in far less time than at -O2 -g
  # (sfm/incremental_mapper.cc: 27 s of CPU against 69 s), which took most of CI's time.
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DTESSERA_WERROR=ON \
        -DTESSERA_SANITIZE=ON -DTESSERA_BUILD_TESTS=ON -DTESSERA_BUILD_BENCHMARKS=OFF \
        "${launcher[@]}" > /dev/null
  cmake --build build-asan -j"$jobs"
  # LeakSanitizer on. intercept_tls_get_addr=0: GCC 12's runtime takes a dynamic TLS
  # block that happens to sit at a certain page offset for one with glibc 2.19's header,
  # reads a bogus range from it, and its tracer dies of SIGSEGV at exit ("Tracer caught
  # signal 11"; "DTLS 45 at 0x2fab-0x18000040ad" under LSAN_OPTIONS=verbosity=1;
  # google/sanitizers#1322, fixed after GCC 13). Without the interception it scans static
  # TLS, stacks, globals and the heap, but not dynamic TLS blocks.
  ASAN_OPTIONS=detect_leaks=1:intercept_tls_get_addr=0 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure -j"$jobs" -LE "slow|install"
fi
