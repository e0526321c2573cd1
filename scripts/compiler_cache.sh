# Sourced by quickstart.sh and test.sh: compile through ccache (installed by
# install_dependencies.sh) with the checkout as the base directory, so that the two
# scripts, and other clones of the same sources, share compiled objects. Sets `launcher`,
# the CMake arguments that name it.
launcher=()
if command -v ccache > /dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=1
fi
