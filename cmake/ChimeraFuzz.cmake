# CHIMERA_FUZZ=ON makes a build tree of the libFuzzer targets (tests/fuzz) and only what they
# need: clang, AddressSanitizer and UndefinedBehaviorSanitizer on every target, coverage
# instrumentation for libFuzzer, and no other tests. `make fuzz` and test.sh's fuzz stage use it.
option(CHIMERA_FUZZ "Build the libFuzzer targets of tests/fuzz (clang only) instead of the tests" OFF)
if(CHIMERA_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "CHIMERA_FUZZ needs clang (libFuzzer), e.g. -DCMAKE_CXX_COMPILER=clang++-14 "
                        "-DCMAKE_C_COMPILER=clang-14; this tree uses ${CMAKE_CXX_COMPILER_ID}")
  endif()
  # A normal variable shadows the cache: the fuzz tree is always sanitized this way.
  set(CHIMERA_SANITIZE "address,undefined")
  # Coverage for libFuzzer in every object; only the targets link libFuzzer's main.
  string(APPEND CMAKE_C_FLAGS " -fsanitize=fuzzer-no-link")
  string(APPEND CMAKE_CXX_FLAGS " -fsanitize=fuzzer-no-link")
  set(CHIMERA_BUILD_TESTS OFF)
endif()
