# Dependencies of pliant's modbus driver (installed as pliant-modbus-dependencies.cmake).
find_dependency(Threads)
find_dependency(PkgConfig)
if(NOT TARGET PkgConfig::PLIANT_LIBMODBUS)
  pkg_check_modules(PLIANT_LIBMODBUS REQUIRED IMPORTED_TARGET GLOBAL libmodbus>=3.1)
endif()
