# tessera_add_plugin(NAME SOURCES src... [LIBRARIES lib...])
#
# Builds a Tessera plugin as a MODULE library. In the Tessera tree the SDK target is
# `tessera_sdk`; for an installed Tessera (find_package(Tessera)) it is `Tessera::sdk`.
# Plugins must be built with the same compiler and standard library as the host:
# C++ objects cross the boundary.
function(tessera_add_plugin name)
  cmake_parse_arguments(ARG "" "OUTPUT_DIRECTORY" "SOURCES;LIBRARIES" ${ARGN})
  add_library(${name} MODULE ${ARG_SOURCES})
  if(TARGET tessera_sdk)
    target_link_libraries(${name} PRIVATE tessera_sdk)
  else()
    target_link_libraries(${name} PRIVATE Tessera::sdk)
  endif()
  target_link_libraries(${name} PRIVATE ${ARG_LIBRARIES})
  # Every symbol resolved at link time: a plugin that uses Tessera::io (or any library)
  # without linking it fails to build, instead of loading only where the host happens to
  # have the library loaded already.
  target_link_options(${name} PRIVATE "LINKER:--no-undefined")
  set_target_properties(${name} PROPERTIES PREFIX "lib" CXX_VISIBILITY_PRESET hidden
                                           VISIBILITY_INLINES_HIDDEN ON)
  if(ARG_OUTPUT_DIRECTORY)
    set_target_properties(${name} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${ARG_OUTPUT_DIRECTORY})
  elseif(DEFINED TESSERA_PLUGIN_OUTPUT_DIR)
    set_target_properties(${name} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${TESSERA_PLUGIN_OUTPUT_DIR})
  endif()
  if(COMMAND tessera_set_compile_options)
    tessera_set_compile_options(${name})
  endif()
endfunction()

# tessera_install_plugin(NAME): installs a bundled plugin next to the host's plugins.
# Installed plugins find libtessera_io.so two folders up (lib/tessera/plugins -> lib).
function(tessera_install_plugin name)
  set_target_properties(${name} PROPERTIES INSTALL_RPATH "$ORIGIN/../..")
  install(TARGETS ${name} LIBRARY DESTINATION ${TESSERA_PLUGIN_SUBDIR})
endfunction()
