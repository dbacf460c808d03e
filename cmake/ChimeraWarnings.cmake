# Warnings for the project's own targets (not for third-party headers, which are system headers).
function(chimera_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -Woverloaded-virtual -Wimplicit-fallthrough)
  if(CHIMERA_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
