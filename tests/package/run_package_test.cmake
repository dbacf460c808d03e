# cmake -DBUILD_DIR=... -DCONSUMER_DIR=... -DWORK_DIR=... -DGENERATOR=... -DCXX_COMPILER=... -P run_package_test.cmake
# Installs BUILD_DIR into WORK_DIR/prefix, builds the consumer against it, runs it, checks its output.
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/steps.cmake)
require_definitions(run_package_test.cmake BUILD_DIR CONSUMER_DIR WORK_DIR GENERATOR CXX_COMPILER)

set(prefix ${WORK_DIR}/prefix)
set(consumer_build ${WORK_DIR}/consumer-build)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

step("package test: install ${BUILD_DIR} into ${prefix}" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
# Only the installed package may be found: no package registry, no system-wide chimera.
step("package test: configure the consumer" ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${consumer_build} -G ${GENERATOR}
     -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
     -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo)
file(STRINGS ${consumer_build}/CMakeCache.txt chimera_dir REGEX "^chimera_DIR:")
if(NOT chimera_dir MATCHES "^chimera_DIR:PATH=${prefix}/")
  message(FATAL_ERROR "package test: the consumer found chimera outside ${prefix}: ${chimera_dir}")
endif()
step("package test: build the consumer" ${CMAKE_COMMAND} --build ${consumer_build})
step("package test: run the consumer" ${consumer_build}/consumer)
message(STATUS "consumer said:\n${step_output}")

foreach(expected
        "module consumer_gain: y = k u, defined outside the Chimera tree"
        "port in-const ndof f64[1]"
        "port in-var u f64[ndof]"
        "port out-var y f64[ndof]"
        "made: yes")
  string(FIND "${step_output}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "package test: the consumer's output lacks \"${expected}\"")
  endif()
endforeach()
message(STATUS "package test: passed")
