# tessera_add_test(NAME SOURCES src... [LIBRARIES lib...] [LABELS label...] [PREFIX p]
#                  [TIMEOUT seconds])
# A GoogleTest executable registered with CTest, test by test; PREFIX starts every CTest
# name (e.g. "exporter." gives exporter.PlyExporter.WritesColours), for `ctest -R`.
# TIMEOUT ends each of its tests that runs longer (e.g. one that would hang on a FIFO).
function(tessera_add_test name)
  cmake_parse_arguments(ARG "" "PREFIX;TIMEOUT" "SOURCES;LIBRARIES;LABELS" ${ARGN})
  # An empty LABELS value would swallow the next property name: each is added when given.
  set(properties "")
  if(ARG_LABELS)
    list(APPEND properties PROPERTIES LABELS "${ARG_LABELS}")
  endif()
  if(ARG_TIMEOUT)
    if(NOT properties)
      list(APPEND properties PROPERTIES)
    endif()
    list(APPEND properties TIMEOUT ${ARG_TIMEOUT})
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBRARIES} GTest::gtest GTest::gtest_main)
  tessera_set_compile_options(${name})
  include(GoogleTest)
  gtest_discover_tests(${name}
    TEST_PREFIX "${ARG_PREFIX}"
    ${properties}
    DISCOVERY_TIMEOUT 60)
endfunction()
