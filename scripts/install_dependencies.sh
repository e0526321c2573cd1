#!/bin/bash
# Installs, by name, the Debian 12 packages Tessera needs to build, test and compare
# against COLMAP. Idempotent: installs only what is missing. Run as root or with sudo.
set -euo pipefail

packages=(
  build-essential cmake pkg-config clang-format ccache
  libopencv-dev libceres-dev libeigen3-dev libboost-dev libboost-filesystem-dev
  nlohmann-json3-dev libflann-dev libsqlite3-dev sqlite3 bc libexif-dev
  libglfw3-dev libimgui-dev libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev libspdlog-dev python3-numpy gnuplot-nox
  libfaiss-dev
  libxxhash-dev
  clang libclang-rt-dev
  xvfb xauth libgl1-mesa-dri
  # The Python module (python/) and its tests and example.
  pybind11-dev python3-dev python3-pytest python3-matplotlib
  # OpenCV's Python API: the features that import_end_to_end and test_import.py import.
  python3-opencv
  # `pip install .` offline (pyproject.toml, setup.py: --no-build-isolation) and the
  # typing test (mypy --strict on examples/python).
  python3-venv python3-setuptools python3-wheel mypy
  # What COLMAP 4 (../shared/anchors/colmap-4/bin/colmap, the reference of `tessera bench
  # --with-colmap` and of colmap4_bench_end_to_end) links at run time: the list of its
  # README.
  libopenimageio2.4 libgoogle-glog0v6 libcholmod3 libspqr2 libcxsparse3 libmetis5
  libboost-program-options1.74.0 libsqlite3-0 libgomp1 libblas3 liblapack3
)
# The reference system, for the interoperability tests and benchmarks, and Open3D, an
# independent PLY reader for the ply exporter's test; optional.
optional_packages=(colmap python3-open3d)
# A one-node Slurm cluster for the Slurm end-to-end test (tests/end_to_end/slurm_test.sh);
# optional: the test skips without it.
optional_packages+=(slurmctld slurmd slurm-client munge)

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi

missing=()
for package in "${packages[@]}" "${optional_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" ||
    missing+=("$package")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_dependencies: all packages present"
  exit 0
fi

echo "install_dependencies: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
required_missing=()
for package in "${missing[@]}"; do
  [[ " ${optional_packages[*]} " == *" $package "* ]] || required_missing+=("$package")
done
if [ ${#required_missing[@]} -gt 0 ]; then
  $sudo apt-get install -y -qq --no-install-recommends "${required_missing[@]}" > /dev/null
fi
for package in "${optional_packages[@]}"; do
  if [[ " ${missing[*]} " == *" $package "* ]]; then
    $sudo apt-get install -y -qq --no-install-recommends "$package" > /dev/null ||
      echo "install_dependencies: WARNING: could not install optional package '$package';" \
           "the tests that need it will be skipped"
  fi
done
