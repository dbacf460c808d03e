# Warnings for the project's own targets (not for third-party headers, which are system headers).
function(chimera_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wimplicit-fallthrough
                                           $<$<COMPILE_LANGUAGE:CXX>:-Wnon-virtual-dtor -Woverloaded-virtual>)
  if(CHIMERA_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
