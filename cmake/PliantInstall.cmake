# Install and export, so that find_package(pliant COMPONENTS ...) works from an install prefix.
# One export set per component (cmake/components/README.md):
#   core       pliant::core, pliant::bridge, pliant::hal (always)
#   host       the host libraries (pliant::recording ... pliant::replay) and pliant::host
#   vision     pliant::vision_webcam, pliant::vision_depth
#   <driver>   pliant::driver_<driver> for each driver built (socketcan, modbus, opencv, libcamera,
#              openni2, usb)
# Each component's dependencies are found again by cmake/components/<component>.cmake, installed
# beside the targets. The `pliant` program is installed too, outside any export set.
# Every file also belongs to one install component, the unit of the Debian packages
# (cmake/PliantPackaging.cmake): core_dev (core, bridge, hal and the package configuration),
# host_dev (host, vision, drivers), cli (the program). `cmake --install` without --component
# installs them all.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
set(pliant_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/pliant)

# pliant_install_component(<component> <target> ...): installs the targets in export set
# pliant-<component>-targets, and the component's dependency script, in install component
# core_dev for core and host_dev for every other.
function(pliant_install_component component)
  set(package host_dev)
  if(component STREQUAL "core")
    set(package core_dev)
  endif()
  install(TARGETS ${ARGN} EXPORT pliant-${component}-targets COMPONENT ${package}
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(EXPORT pliant-${component}-targets NAMESPACE pliant:: DESTINATION ${pliant_cmake_dir} COMPONENT ${package})
  if(EXISTS ${PROJECT_SOURCE_DIR}/cmake/components/${component}.cmake)
    install(FILES ${PROJECT_SOURCE_DIR}/cmake/components/${component}.cmake
      DESTINATION ${pliant_cmake_dir} RENAME pliant-${component}-dependencies.cmake COMPONENT ${package})
  endif()
  set(PLIANT_INSTALLED_COMPONENTS ${PLIANT_INSTALLED_COMPONENTS} ${component} PARENT_SCOPE)
endfunction()

set(PLIANT_INSTALLED_COMPONENTS "")
pliant_install_component(core pliant_core pliant_bridge pliant_hal)
install(DIRECTORY core/include/pliant DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT core_dev)
install(DIRECTORY hal/include/pliant DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT core_dev)
install(DIRECTORY firmware-bridge/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT core_dev
  FILES_MATCHING PATTERN "*.h")

if(PLIANT_BUILD_HOST AND PLIANT_HOST_LIBRARIES)
  pliant_install_component(host ${PLIANT_HOST_LIBRARIES} pliant_host)
  install(DIRECTORY host/include/pliant DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT host_dev)
  set(pliant_vision_targets "")
  foreach(part webcam depth)
    if(TARGET pliant_vision_${part})
      list(APPEND pliant_vision_targets pliant_vision_${part})
      install(DIRECTORY host/vision/${part}/include/pliant DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT host_dev)
    endif()
  endforeach()
  if(pliant_vision_targets)
    pliant_install_component(vision ${pliant_vision_targets})
  endif()
  if(TARGET pliant)
    install(TARGETS pliant RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT cli)
  endif()
endif()

foreach(driver socketcan modbus opencv libcamera openni2 usb)
  if(TARGET pliant_driver_${driver})
    pliant_install_component(${driver} pliant_driver_${driver})
    install(DIRECTORY drivers/${driver}/include/pliant DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT host_dev
      PATTERN emulator EXCLUDE)  # the device emulators are test peers, not installed
  endif()
endforeach()

configure_package_config_file(cmake/pliantConfig.cmake.in
  ${PROJECT_BINARY_DIR}/pliantConfig.cmake
  INSTALL_DESTINATION ${pliant_cmake_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/pliantConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/pliantConfig.cmake ${PROJECT_BINARY_DIR}/pliantConfigVersion.cmake
  DESTINATION ${pliant_cmake_dir} COMPONENT core_dev)
