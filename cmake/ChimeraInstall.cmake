# Installs the runtime and its public headers, and exports the `chimera` package so that
# find_package(chimera) works for projects outside the tree (modules built as plugins):
#   find_package(chimera 0.1 REQUIRED)
#   target_link_libraries(my_module PRIVATE chimera::chimera)
# tests/package builds such a project against an install of the build tree.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(_chimera_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/chimera)

install(TARGETS chimera_lib EXPORT chimeraTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# Not chimera/net: the network API is the chimera command's (src/net), not part of libchimera.
install(DIRECTORY include/chimera DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} PATTERN net EXCLUDE)
install(FILES ${CHIMERA_GENERATED_INCLUDE_DIR}/chimera/module_abi.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/chimera)
install(EXPORT chimeraTargets NAMESPACE chimera:: DESTINATION ${_chimera_cmake_dir})

# The installed chimera command finds libchimera beside it in any prefix, not only in /usr.
if(TARGET chimera_cli)
  set_target_properties(chimera_cli PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
endif()

configure_package_config_file(cmake/chimeraConfig.cmake.in ${PROJECT_BINARY_DIR}/chimeraConfig.cmake
                              INSTALL_DESTINATION ${_chimera_cmake_dir})
# Before 1.0 a minor version may break the API, so 0.1 accepts 0.1.x only.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/chimeraConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/chimeraConfig.cmake ${PROJECT_BINARY_DIR}/chimeraConfigVersion.cmake
        DESTINATION ${_chimera_cmake_dir})
