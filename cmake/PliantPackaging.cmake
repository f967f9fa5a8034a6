# Debian packages of an installed pliant, made by CPack from the install components of
# cmake/PliantInstall.cmake (docs/packages.md):
#   libpliant-core-dev  core_dev   controller code: pliant::core, pliant::bridge, pliant::hal (static
#                                  libraries, headers, pliant.h, pliant-bridge.pc) and the CMake
#                                  package configuration every component loads first
#   libpliant-dev       host_dev   the host libraries, vision and the drivers that were built,
#                                  with their headers and CMake component scripts
#   pliant              cli        the `pliant` command line
#   python3-pliant      python     the Python module pliant (host/python) in
#                                  /usr/lib/python3/dist-packages/pliant
# The libraries are static, so the -dev packages depend on the -dev packages a consumer links
# against (the list below follows what was built); the program's and the Python extension's
# run-time dependencies are read off the binaries by dpkg-shlibdeps.
# Usage: cmake --build build && (cd build && cpack -G DEB)   or   bash tools/test.sh package
set(CPACK_PACKAGE_NAME pliant)
set(CPACK_PACKAGE_VENDOR "pliant")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "learn how soft an object is from what a robot sees and feels")
set(CPACK_PACKAGE_CONTACT "pliant maintainers <pliant@localhost>")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_GENERATOR DEB)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_ENABLE_COMPONENT_DEPENDS OFF)  # the Depends lines below name our packages themselves

set(pliant_same_version "(= ${PROJECT_VERSION})")

set(CPACK_DEBIAN_CORE_DEV_PACKAGE_NAME libpliant-core-dev)
set(CPACK_DEBIAN_CORE_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_CORE_DEV_PACKAGE_DEPENDS "libeigen3-dev (>= 3.3)")
set(CPACK_COMPONENT_CORE_DEV_DESCRIPTION
    "pliant controller libraries: meshless shape matching, deformability estimation, grasp guard, HAL, C ABI")

# pliant_debian_depends(<variable> <target-or-ALWAYS> <package> ...): appends the packages when
# the target was built (or always).
macro(pliant_debian_depends variable target)
  if("${target}" STREQUAL "ALWAYS" OR TARGET ${target})
    list(APPEND ${variable} ${ARGN})
  endif()
endmacro()

set(pliant_host_depends "libpliant-core-dev ${pliant_same_version}")
pliant_debian_depends(pliant_host_depends pliant_recording nlohmann-json3-dev)
pliant_debian_depends(pliant_host_depends pliant_mesh libtet1.5-dev)
pliant_debian_depends(pliant_host_depends pliant_fit libceres-dev)
pliant_debian_depends(pliant_host_depends pliant_fem libspectra-dev)
pliant_debian_depends(pliant_host_depends pliant_vision_depth libnanoflann-dev libpng-dev)
pliant_debian_depends(pliant_host_depends pliant_vision_webcam libopencv-dev)
pliant_debian_depends(pliant_host_depends pliant_driver_opencv libopencv-dev)
pliant_debian_depends(pliant_host_depends pliant_driver_modbus libmodbus-dev)
pliant_debian_depends(pliant_host_depends pliant_driver_usb libusb-1.0-0-dev)
pliant_debian_depends(pliant_host_depends pliant_driver_libcamera libcamera-dev)
pliant_debian_depends(pliant_host_depends pliant_driver_openni2 libopenni2-dev)
list(REMOVE_DUPLICATES pliant_host_depends)
list(JOIN pliant_host_depends ", " CPACK_DEBIAN_HOST_DEV_PACKAGE_DEPENDS)
set(CPACK_DEBIAN_HOST_DEV_PACKAGE_NAME libpliant-dev)
set(CPACK_DEBIAN_HOST_DEV_PACKAGE_SECTION libdevel)
set(CPACK_COMPONENT_HOST_DEV_DESCRIPTION
    "pliant host libraries: recordings, FEM refinement, missing-physics diagnosis, vision, device drivers")

set(CPACK_DEBIAN_CLI_PACKAGE_NAME pliant)
set(CPACK_DEBIAN_CLI_PACKAGE_SHLIBDEPS ON)
set(CPACK_COMPONENT_CLI_DESCRIPTION "the pliant command line: estimate, diagnose, refine, simulate, record, replay")

# The extension is built for one Python (its file name carries the ABI, cpython-311-...), so the
# package wants that minor version; the host libraries are linked into it, so it needs no other
# pliant package. Its destination is relative (host/python/CMakeLists.txt), so CPack's prefix /usr
# puts it in /usr/lib/python3/dist-packages/pliant whatever CMAKE_INSTALL_PREFIX the build has.
set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-pliant)
set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
set(CPACK_DEBIAN_PYTHON_PACKAGE_SHLIBDEPS ON)
if(PLIANT_PYTHON_VERSION)
  string(REPLACE "." ";" pliant_python_version_parts "${PLIANT_PYTHON_VERSION}")
  list(GET pliant_python_version_parts 0 pliant_python_major)
  list(GET pliant_python_version_parts 1 pliant_python_minor)
  math(EXPR pliant_python_next_minor "${pliant_python_minor} + 1")
  set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS
      "python3 (>= ${PLIANT_PYTHON_VERSION}), python3 (<< ${pliant_python_major}.${pliant_python_next_minor}), python3-numpy")
endif()
# The fleet (pliant.fleet, docs/fleet.md) runs the command line's jobs on Dask: it works with them
# installed, and the rest of the module does not need them.
set(CPACK_DEBIAN_PYTHON_PACKAGE_RECOMMENDS "pliant (= ${PROJECT_VERSION}), python3-distributed, python3-tqdm")
set(CPACK_COMPONENT_PYTHON_DESCRIPTION
    "pliant for Python: recordings as NumPy arrays, estimate, diagnose, refine, simulate, online estimator, grasp guard")

# host_dev holds the host libraries and every driver built; a build without either has no
# libpliant-dev (a controller-only build).
set(CPACK_COMPONENTS_ALL core_dev)
set(pliant_has_host_dev FALSE)
if(PLIANT_BUILD_HOST AND PLIANT_HOST_LIBRARIES)
  set(pliant_has_host_dev TRUE)
endif()
foreach(driver socketcan modbus opencv libcamera openni2 usb)
  if(TARGET pliant_driver_${driver})
    set(pliant_has_host_dev TRUE)
  endif()
endforeach()
if(pliant_has_host_dev)
  list(APPEND CPACK_COMPONENTS_ALL host_dev)
endif()
if(PLIANT_BUILD_HOST AND TARGET pliant)
  list(APPEND CPACK_COMPONENTS_ALL cli)
endif()
if(TARGET _pliant)
  list(APPEND CPACK_COMPONENTS_ALL python)
endif()

include(CPack)
