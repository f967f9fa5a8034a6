# Dependencies of pliant's usb driver (installed as pliant-usb-dependencies.cmake).
find_dependency(PkgConfig)
if(NOT TARGET PkgConfig::PLIANT_LIBUSB)
  pkg_check_modules(PLIANT_LIBUSB REQUIRED IMPORTED_TARGET GLOBAL libusb-1.0>=1.0.20)
endif()
