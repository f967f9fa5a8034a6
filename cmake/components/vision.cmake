# Dependencies of pliant's vision front ends (installed as pliant-vision-dependencies.cmake).
find_dependency(OpenCV COMPONENTS core imgproc video videoio imgcodecs)
find_dependency(PNG)
find_package(nanoflann QUIET)  # header-only; Debian's libnanoflann-dev ships its CMake config
