# pliant.h and its implementation (C++17 behind an extern "C" interface), its pkg-config file
# and install rules. Included from firmware-bridge/CMakeLists.txt (target pliant_bridge).
option(PLIANT_BRIDGE_DOUBLE "pliant_bridge computes in double (ON) or float (OFF); pliant.h is the same" ON)

target_sources(pliant_bridge PRIVATE
  ${CMAKE_CURRENT_SOURCE_DIR}/src/status.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/config.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/layout.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/lifecycle.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/frame.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/estimate.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/guard.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/counters.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/src/telemetry_emit.cpp)
if(PLIANT_BRIDGE_DOUBLE)
  set(PLIANT_BRIDGE_SCALAR_DOUBLE 1)
else()
  set(PLIANT_BRIDGE_SCALAR_DOUBLE 0)
endif()
target_compile_definitions(pliant_bridge PRIVATE
  PLIANT_BRIDGE_SCALAR_DOUBLE=${PLIANT_BRIDGE_SCALAR_DOUBLE}
  PLIANT_PROJECT_VERSION_MAJOR=${PROJECT_VERSION_MAJOR}
  PLIANT_PROJECT_VERSION_MINOR=${PROJECT_VERSION_MINOR}
  PLIANT_PROJECT_VERSION_PATCH=${PROJECT_VERSION_PATCH})
# Same flag as the core: sqrt without errno (pliant never reads errno).
target_compile_options(pliant_bridge PRIVATE $<$<AND:$<COMPILE_LANGUAGE:CXX>,$<CXX_COMPILER_ID:GNU,Clang,AppleClang>>:-fno-math-errno>)

# pkg-config for C users (pliant.h is pure C, so no Eigen). Installed with the library; the
# prefix is found relative to the .pc file, so an install moved with --prefix still works.
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}" OR IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(PLIANT_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
  set(PLIANT_PC_LIBDIR "${CMAKE_INSTALL_FULL_LIBDIR}")
  set(PLIANT_PC_INCLUDEDIR "${CMAKE_INSTALL_FULL_INCLUDEDIR}")
else()
  file(RELATIVE_PATH pliant_pc_up "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
  string(REGEX REPLACE "/$" "" pliant_pc_up "${pliant_pc_up}")
  set(PLIANT_PC_PREFIX "\${pcfiledir}/${pliant_pc_up}")
  set(PLIANT_PC_LIBDIR "\${prefix}/${CMAKE_INSTALL_LIBDIR}")
  set(PLIANT_PC_INCLUDEDIR "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
endif()
configure_file(${CMAKE_CURRENT_SOURCE_DIR}/pliant-bridge.pc.in ${CMAKE_CURRENT_BINARY_DIR}/pliant-bridge.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/pliant-bridge.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig
  COMPONENT core_dev)
