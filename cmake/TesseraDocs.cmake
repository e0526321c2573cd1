# tessera_install_docs(DOCDIR): installs the plugin author's documentation under DOCDIR
# (component sdk_docs):
#   DOCDIR/plugin_authors_guide.md, DOCDIR/manifest_reference.md  (docs/)
#   DOCDIR/plugins/<kind>.md                                      (docs/plugins/)
#   DOCDIR/plugins/<kind>/<name>.md                               (plugins/<kind>/<name>/README.md)
# Links between them are written for the source tree; each page is copied to
# build/doc/ with those links rewritten for the installed tree, and installed from
# there. scripts/check_installed_docs.py checks that every relative link resolves.

# tessera_rewrite_doc(SOURCE OUTPUT ROLE): ROLE is "top" (docs/*.md), "kind"
# (docs/plugins/*.md) or "plugin" (a plugin's README).
function(tessera_rewrite_doc source output role)
  file(READ ${source} text)
  set(readme "([a-z_]+)/([a-z_]+)/README\\.md")
  if(role STREQUAL "top")
    string(REGEX REPLACE "\\]\\(\\.\\./plugins/${readme}" "](plugins/\\1/\\2.md" text "${text}")
  elseif(role STREQUAL "kind")
    string(REGEX REPLACE "\\]\\(\\.\\./\\.\\./plugins/${readme}" "](\\1/\\2.md" text "${text}")
  else()
    string(REPLACE "](../../../docs/plugins/" "](../" text "${text}")
    string(REPLACE "](../../../docs/" "](../../" text "${text}")
    string(REGEX REPLACE "\\]\\(\\.\\./\\.\\./${readme}" "](../\\1/\\2.md" text "${text}")
    string(REGEX REPLACE "\\]\\(\\.\\./([a-z_]+)/README\\.md" "](\\1.md" text "${text}")
  endif()
  file(WRITE ${output} "${text}")
  set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${source})
endfunction()

function(tessera_install_docs docdir)
  set(out ${CMAKE_BINARY_DIR}/doc)
  foreach(page plugin_authors_guide.md manifest_reference.md)
    tessera_rewrite_doc(${PROJECT_SOURCE_DIR}/docs/${page} ${out}/${page} top)
    install(FILES ${out}/${page} DESTINATION ${docdir} COMPONENT sdk_docs)
  endforeach()
  file(GLOB kind_pages RELATIVE ${PROJECT_SOURCE_DIR}/docs/plugins
       ${PROJECT_SOURCE_DIR}/docs/plugins/*.md)
  foreach(page ${kind_pages})
    tessera_rewrite_doc(${PROJECT_SOURCE_DIR}/docs/plugins/${page} ${out}/plugins/${page} kind)
    install(FILES ${out}/plugins/${page} DESTINATION ${docdir}/plugins COMPONENT sdk_docs)
  endforeach()
  file(GLOB readmes RELATIVE ${PROJECT_SOURCE_DIR}/plugins
       ${PROJECT_SOURCE_DIR}/plugins/*/*/README.md)
  foreach(readme ${readmes})
    get_filename_component(folder ${readme} DIRECTORY)  # kind/name
    get_filename_component(kind ${folder} DIRECTORY)
    get_filename_component(name ${folder} NAME)
    tessera_rewrite_doc(${PROJECT_SOURCE_DIR}/plugins/${readme} ${out}/plugins/${kind}/${name}.md
                        plugin)
    install(FILES ${out}/plugins/${kind}/${name}.md DESTINATION ${docdir}/plugins/${kind}
            COMPONENT sdk_docs)
  endforeach()
endfunction()
