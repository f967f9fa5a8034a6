# Dependencies of pliant's openni2 driver (installed as pliant-openni2-dependencies.cmake): OpenNI2
# by pkg-config, or by its header and library where no .pc file exists, under the names the driver
# was built with.
find_package(PkgConfig QUIET)
if(PKG_CONFIG_FOUND AND NOT TARGET PkgConfig::PLIANT_OPENNI2)
  pkg_check_modules(PLIANT_OPENNI2 QUIET IMPORTED_TARGET GLOBAL libopenni2)
endif()
if(NOT TARGET PkgConfig::PLIANT_OPENNI2 AND NOT TARGET pliant_openni2_library)
  find_path(PLIANT_OPENNI2_INCLUDE_DIR OpenNI.h PATH_SUFFIXES openni2)
  find_library(PLIANT_OPENNI2_LIBRARY OpenNI2)
  if(NOT PLIANT_OPENNI2_INCLUDE_DIR OR NOT PLIANT_OPENNI2_LIBRARY)
    set(pliant_openni2_FOUND FALSE)
    set(pliant_openni2_NOT_FOUND_MESSAGE "OpenNI2 not found (Debian: libopenni2-dev)")
    return()
  endif()
  add_library(pliant_openni2_library UNKNOWN IMPORTED GLOBAL)
  set_target_properties(pliant_openni2_library PROPERTIES
    IMPORTED_LOCATION ${PLIANT_OPENNI2_LIBRARY} INTERFACE_INCLUDE_DIRECTORIES ${PLIANT_OPENNI2_INCLUDE_DIR})
endif()
