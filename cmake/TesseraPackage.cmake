# A Debian package of the installed tree: `cpack -G DEB` in a Release build folder
# writes tessera_<version>_<arch>.deb, which `apt install ./tessera_*.deb` installs on
# Debian 12 with the packages it needs. It holds everything `cmake --install` puts under
# /usr: the CLI, the host libraries, the bundled plugins, the recipes, the Python module,
# and the SDK (headers, CMake package, guides and example plugins) for plugin authors.
# benchmarks/deb_install.sh installs it into a fresh debootstrap root and runs the sample.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME tessera)
set(CPACK_PACKAGE_VENDOR Tessera)
set(CPACK_PACKAGE_CONTACT "Tessera developers")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Structure-from-Motion whose every stage is a runtime-loaded plugin")
set(CPACK_PACKAGE_DESCRIPTION
    "Tessera reconstructs cameras and a sparse point cloud from photographs or video, and\
 exports COLMAP models, PLY, Gaussian Splatting workspaces and transforms.json. Detectors,\
 matchers, pair selection, mappers, bundle adjusters and exporters are plugins named in a\
 JSON manifest. Includes the `tessera` command line and GUI, the bundled plugins and\
 recipes, the Python module and the SDK for writing plugins.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
# Depends: the Debian packages of the shared libraries that the binaries link, found by
# dpkg-shlibdeps (libopencv-core406, libceres3, libspdlog1.10 ...). The host's own
# libraries travel in the package; the binaries find them through their RUNPATH.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS_PRIVATE_DIRS
    ${CMAKE_BINARY_DIR}/${CMAKE_INSTALL_LIBDIR} ${CMAKE_BINARY_DIR}/${CMAKE_INSTALL_LIBDIR}/tessera)
# What `import tessera` needs besides the shared libraries; what a plugin author's
# find_package(Tessera) needs (the SDK headers include these libraries' headers).
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "python3 (>= 3.11), python3-numpy")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS
    "cmake, g++, nlohmann-json3-dev, libeigen3-dev, libboost-dev, libceres-dev, libopencv-dev, libspdlog-dev")
include(CPack)
