# tessera_add_test(NAME SOURCES src... [LIBRARIES lib...] [LABELS label...] [PREFIX p])
# A GoogleTest executable registered with CTest, test by test; PREFIX starts every CTest
# name (e.g. "exporter." gives exporter.PlyExporter.WritesColours), for `ctest -R`.
function(tessera_add_test name)
  cmake_parse_arguments(ARG "" "PREFIX" "SOURCES;LIBRARIES;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBRARIES} GTest::gtest GTest::gtest_main)
  tessera_set_compile_options(${name})
  include(GoogleTest)
  gtest_discover_tests(${name}
    TEST_PREFIX "${ARG_PREFIX}"
    PROPERTIES LABELS "${ARG_LABELS}"
    DISCOVERY_TIMEOUT 60)
endfunction()
