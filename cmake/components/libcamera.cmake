# Dependencies of pliant's libcamera driver (installed as pliant-libcamera-dependencies.cmake).
find_dependency(PkgConfig)
if(NOT TARGET PkgConfig::LIBCAMERA)
  pkg_check_modules(LIBCAMERA REQUIRED IMPORTED_TARGET GLOBAL libcamera)
endif()
