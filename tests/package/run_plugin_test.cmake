# cmake -DBUILD_DIR=... -DWORK_DIR=... -DGENERATOR=... -DC_COMPILER=... -DCXX_COMPILER=...
#       [-DC_FLAGS=...] [-DCXX_FLAGS=...] [-DMODULE_LINKER_FLAGS=...] -P run_plugin_test.cmake
# Installs BUILD_DIR into WORK_DIR/prefix; the installed `chimera new-module` writes a C++ and a C
# module; each is built against the install and loaded by the installed chimera, which must list
# it (chimera modules) and run it (chimera run on the virtual clock, values checked).
cmake_minimum_required(VERSION 3.25)
include(${CMAKE_CURRENT_LIST_DIR}/steps.cmake)
require_definitions(run_plugin_test.cmake BUILD_DIR WORK_DIR GENERATOR C_COMPILER CXX_COMPILER)

set(prefix ${WORK_DIR}/prefix)
set(chimera ${prefix}/bin/chimera)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

function(expect what text regex)
  if(NOT text MATCHES "${regex}")
    message(FATAL_ERROR "plugin test: ${what}: no match for \"${regex}\" in:\n${text}")
  endif()
endfunction()

step("plugin test: install ${BUILD_DIR} into ${prefix}" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# Names of their own: a subsystem owns the shared memory of its name, and other trees may run
# this test at the same time.
string(RANDOM LENGTH 8 ALPHABET abcdefghijklmnopqrstuvwxyz0123456789 tag)
set(cpp_module oot_gain_${tag})
set(c_module oot_filter_${tag})
step("plugin test: chimera new-module ${cpp_module}" ${chimera} new-module ${cpp_module} --dir ${WORK_DIR})
step("plugin test: chimera new-module ${c_module} --lang c" ${chimera} new-module ${c_module} --lang c --dir ${WORK_DIR})

foreach(module ${cpp_module} ${c_module})
  # Only the installed package may be found: no package registry, no system-wide chimera.
  step("plugin test: configure ${module}" ${CMAKE_COMMAND} -S ${WORK_DIR}/${module} -B ${WORK_DIR}/${module}/build -G ${GENERATOR}
       -DCMAKE_C_COMPILER=${C_COMPILER} -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_PREFIX_PATH=${prefix}
       -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_FIND_USE_SYSTEM_PACKAGE_REGISTRY=OFF
       "-DCMAKE_C_FLAGS=${C_FLAGS}" "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}" "-DCMAKE_MODULE_LINKER_FLAGS=${MODULE_LINKER_FLAGS}")
  file(STRINGS ${WORK_DIR}/${module}/build/CMakeCache.txt chimera_dir REGEX "^chimera_DIR:")
  if(NOT chimera_dir MATCHES "^chimera_DIR:PATH=${prefix}/")
    message(FATAL_ERROR "plugin test: ${module} found chimera outside ${prefix}: ${chimera_dir}")
  endif()
  step("plugin test: build ${module}" ${CMAKE_COMMAND} --build ${WORK_DIR}/${module}/build)
endforeach()

set(path "CHIMERA_MODULE_PATH=${WORK_DIR}/${cpp_module}/build:${WORK_DIR}/${c_module}/build")
step("plugin test: chimera modules" ${CMAKE_COMMAND} -E env ${path} ${chimera} modules)
expect("chimera modules" "${step_output}" "${cpp_module} +y = k u, channel by channel +${WORK_DIR}/${cpp_module}/build/lib${cpp_module}.so")
expect("chimera modules" "${step_output}" "${c_module} +first-order low-pass filter, in C +${WORK_DIR}/${c_module}/build/lib${c_module}.so")
expect("chimera modules" "${step_output}" "pid_joint .*\\(built in\\)")
step("plugin test: chimera modules ${c_module}" ${CMAKE_COMMAND} -E env ${path} ${chimera} modules ${c_module})
expect("chimera modules ${c_module}" "${step_output}" "in-var +u +f64 +ndof")

# The subsystem files the template wrote name the libraries in plugins: and feed u = [1, 2, 3].
file(WRITE ${WORK_DIR}/script.txt "wait 30ms\nget y\nwait 970ms\nget y\nquit\n")
step("plugin test: chimera run ${cpp_module}.yaml" INPUT ${WORK_DIR}/script.txt
     ${CMAKE_COMMAND} -E env ${path} ${chimera} run ${WORK_DIR}/${cpp_module}/${cpp_module}.yaml --clock virtual --for 2s)
expect("${cpp_module}: y = 2 u" "${step_output}" "y = \\[2, 4, 6\\]\ny = \\[2, 4, 6\\]")
step("plugin test: chimera run ${c_module}.yaml" INPUT ${WORK_DIR}/script.txt
     ${CMAKE_COMMAND} -E env ${path} ${chimera} run ${WORK_DIR}/${c_module}/${c_module}.yaml --clock virtual --for 2s)
# After 3 or 4 cycles of 10 ms with tau = 0.1 s the filter is about a quarter of the way; after
# 100 cycles within 1e-4 of u.
expect("${c_module}: on its way" "${step_output}" "y = \\[0\\.[23][0-9]*, 0\\.[4-6][0-9]*, 0\\.[7-9][0-9]*\\]")
expect("${c_module}: arrived" "${step_output}" "y = \\[0\\.9999[0-9]*, 1\\.999[0-9]*, 2\\.999[0-9]*\\]")
message(STATUS "plugin test: passed")
