# Compiler flags shared by the host, the bundled plugins and third-party plugins.
function(tessera_set_compile_options target)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  if(TESSERA_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(TESSERA_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer
                                             -fno-sanitize-recover=undefined)
    # GCC 12 at the sanitizer build's optimisation level reports -Wmaybe-uninitialized
    # inside libstdc++'s <regex> (std::function in _State); GCC's manual warns that
    # -fsanitize makes this warning give false positives. Release builds keep it.
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      target_compile_options(${target} PRIVATE -Wno-maybe-uninitialized)
    endif()
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
endfunction()
