# The module ABI fingerprint: a hash of every header in a module author's include graph (the
# headers a module library compiles against) and of the project's version. The registration
# macro stamps it into each module library, and the loader refuses a library whose stamp differs
# from its own (src/module/registry.cpp): a library built against another version of these
# headers (an extra virtual method in Module, a field more in InitContext) would load and then
# crash. Any edit to these headers changes it; rebuilding the library is the cure.

# chimera_module_abi(OUTPUT INCLUDE_ROOT VERSION): writes OUTPUT (chimera/module_abi.hpp) from the
# ABI headers found below INCLUDE_ROOT.
function(chimera_module_abi output include_root version)
  set(CHIMERA_MODULE_ABI_HEADERS
      chimera/core/invariant.hpp chimera/core/result.hpp
      chimera/svt/elem_type.hpp chimera/svt/freshness.hpp chimera/svt/port_access.hpp chimera/svt/port_kind.hpp
      chimera/svt/view.hpp
      chimera/module/declarations.hpp chimera/module/fault_tolerance.hpp chimera/module/module.hpp
      chimera/module/params.hpp chimera/module/registry.hpp)
  set(text "chimera ${version}\n")
  foreach(header IN LISTS CHIMERA_MODULE_ABI_HEADERS)
    file(READ ${include_root}/${header} content)
    string(APPEND text "${header}\n${content}\n")
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${include_root}/${header})
  endforeach()
  string(SHA256 digest "${text}")
  string(SUBSTRING "${digest}" 0 16 CHIMERA_MODULE_ABI_FINGERPRINT)
  set(CHIMERA_ABI_VERSION_TEXT "${version}")
  configure_file(${PROJECT_SOURCE_DIR}/cmake/module_abi.hpp.in ${output} @ONLY)
endfunction()
