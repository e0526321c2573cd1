#!/bin/bash
# Installs what is needed, builds Tessera, and runs it on the small sample that ships
# in examples/. The workspace lands in ./sample-output.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install_dependencies.sh
source scripts/compiler_cache.sh
# What the sample needs: the CLI, the host libraries, the bundled plugins and the GUI,
# with test.sh's compile options, so that each reuses the other's objects through ccache.
# The Python module is `pip install .`'s to build (README, "From Python").
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DTESSERA_WERROR=ON -DTESSERA_BUILD_TESTS=OFF \
      -DTESSERA_BUILD_BENCHMARKS=OFF -DTESSERA_BUILD_PYTHON=OFF "${launcher[@]}" > /dev/null
cmake --build build -j"$(nproc)"
./build/bin/tessera plugins
./build/bin/tessera run --images examples/fountain-P11-small/images \
  --camera-K examples/fountain-P11-small/K.txt --output sample-output
echo "Workspace written to $(pwd)/sample-output"
