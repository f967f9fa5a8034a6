# Install and export so that find_package(pliant) works from an install prefix.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(PLIANT_INSTALL_TARGETS pliant_core pliant_bridge pliant_hal)
if(PLIANT_BUILD_HOST)
  list(APPEND PLIANT_INSTALL_TARGETS pliant_host pliant)
endif()
install(TARGETS ${PLIANT_INSTALL_TARGETS} EXPORT pliantTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY core/include/pliant DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY hal/include/pliant DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY firmware-bridge/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.h")
if(PLIANT_BUILD_HOST)
  install(DIRECTORY host/include/pliant DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endif()
install(EXPORT pliantTargets NAMESPACE pliant:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/pliant)
configure_package_config_file(cmake/pliantConfig.cmake.in
  ${PROJECT_BINARY_DIR}/pliantConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/pliant)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/pliantConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/pliantConfig.cmake ${PROJECT_BINARY_DIR}/pliantConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/pliant)
