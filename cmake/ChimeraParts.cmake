# The runtime's parts, one library target each, in the paper's order (docs/architecture.md):
#   core -> svt -> module -> lifecycle -> config -> analysis -> exec -> reconfig -> control
# A part sees the public headers of the parts it names in DEPENDS (and theirs, transitively), the
# few headers those parts EXPORT to the parts above them, and its own folder; nothing else. So an
# include against the layering (exec including reconfig, module including config) fails to build.
#
# Each part's include root is a folder of the build tree, layers/<part>/, made of links:
#   layers/<part>/chimera/<part>  ->  include/chimera/<part>     its public (installed) headers
#   layers/<part>/<part>/X.hpp    ->  src/<part>/X.hpp           each header it EXPORTS, by name
# Its own sources include their private headers by bare name ("real_worker.hpp"); the parts above
# include an exported header as "<part>/X.hpp". An exported header can itself include only public
# headers and other exported ones: what it drags in is what the parts above see.
#
# The parts are static (position-independent) libraries linked whole into one shared library,
# libchimera (chimera_lib, chimera::chimera), which is what the modules, the command and users link.
# A part marked APART sits above the runtime and stays out of libchimera: its library is linked
# only by the programs that use it (net: the network API, so that users never link civetweb).

set(CHIMERA_LAYERS_DIR ${PROJECT_BINARY_DIR}/layers)

# chimera_part(NAME [APART] SOURCES src... [DEPENDS part...] [EXPORTS header...] [INCLUDES dir...]
#              [LIBS lib...] [PUBLIC_LIBS lib...])
# DEPENDS names the parts below it that it builds on; what those build on comes along (their
# headers include it). INCLUDES adds include roots of its own (generated headers). The parts do not
# link each other: they meet in libchimera, so the include paths alone decide what a part may use.
function(chimera_part name)
  cmake_parse_arguments(P "APART" "" "SOURCES;DEPENDS;EXPORTS;INCLUDES;LIBS;PUBLIC_LIBS" ${ARGN})
  set(target chimera_${name})
  set(stage ${CHIMERA_LAYERS_DIR}/${name})
  file(REMOVE_RECURSE ${stage})
  file(MAKE_DIRECTORY ${stage}/chimera)
  if(EXISTS ${PROJECT_SOURCE_DIR}/include/chimera/${name})
    file(CREATE_LINK ${PROJECT_SOURCE_DIR}/include/chimera/${name} ${stage}/chimera/${name} SYMBOLIC)
  endif()
  foreach(header IN LISTS P_EXPORTS)
    if(NOT EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${header})
      message(FATAL_ERROR "part ${name} exports ${header}, which is not in ${CMAKE_CURRENT_SOURCE_DIR}")
    endif()
    get_filename_component(sub ${header} DIRECTORY)
    file(MAKE_DIRECTORY ${stage}/${name}/${sub})
    file(CREATE_LINK ${CMAKE_CURRENT_SOURCE_DIR}/${header} ${stage}/${name}/${header} SYMBOLIC)
  endforeach()

  add_library(${target} STATIC ${P_SOURCES})
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  set(includes ${stage} ${P_INCLUDES})
  set(libs ${P_PUBLIC_LIBS})
  foreach(dep IN LISTS P_DEPENDS)
    get_property(dep_includes GLOBAL PROPERTY CHIMERA_PART_${dep}_INCLUDES)
    get_property(dep_libs GLOBAL PROPERTY CHIMERA_PART_${dep}_LIBS)
    if(NOT dep_includes)
      message(FATAL_ERROR "part ${name} depends on ${dep}, which is not a part defined before it")
    endif()
    list(APPEND includes ${dep_includes})
    list(APPEND libs ${dep_libs})
  endforeach()
  list(REMOVE_DUPLICATES includes)
  list(REMOVE_DUPLICATES libs)
  # What the parts above see of this one: it and everything below it.
  set_property(GLOBAL PROPERTY CHIMERA_PART_${name}_INCLUDES ${includes})
  set_property(GLOBAL PROPERTY CHIMERA_PART_${name}_LIBS ${libs})
  target_include_directories(${target} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR} ${includes})
  target_link_libraries(${target} PRIVATE ${libs} ${P_LIBS} Threads::Threads)
  target_compile_features(${target} PUBLIC cxx_std_20)
  chimera_warnings(${target})
  if(NOT P_APART)
    set_property(GLOBAL APPEND PROPERTY CHIMERA_PARTS ${target})
  endif()
endfunction()
