# CHIMERA_SANITIZE=address,undefined or thread applies to every target of this build tree.
if(CHIMERA_SANITIZE)
  set(_san "-fsanitize=${CHIMERA_SANITIZE} -fno-omit-frame-pointer -g1")
  if(CHIMERA_SANITIZE MATCHES "undefined")
    string(APPEND _san " -fno-sanitize-recover=undefined")
  endif()
  string(APPEND CMAKE_C_FLAGS " ${_san}")
  string(APPEND CMAKE_CXX_FLAGS " ${_san}")
  string(APPEND CMAKE_EXE_LINKER_FLAGS " -fsanitize=${CHIMERA_SANITIZE}")
  string(APPEND CMAKE_SHARED_LINKER_FLAGS " -fsanitize=${CHIMERA_SANITIZE}")
  string(APPEND CMAKE_MODULE_LINKER_FLAGS " -fsanitize=${CHIMERA_SANITIZE}")  # libraries loaded with dlopen
endif()
