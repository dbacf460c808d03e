# Installs the runtime and its public headers, and exports the `chimera` package so that
# find_package(chimera) works for projects outside the tree (modules built as plugins).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
install(TARGETS chimera_lib EXPORT chimeraTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY include/chimera DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT chimeraTargets NAMESPACE chimera:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/chimera)
configure_package_config_file(cmake/chimeraConfig.cmake.in ${PROJECT_BINARY_DIR}/chimeraConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/chimera)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/chimeraConfigVersion.cmake COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/chimeraConfig.cmake ${PROJECT_BINARY_DIR}/chimeraConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/chimera)
