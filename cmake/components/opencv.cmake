# Dependencies of pliant's opencv driver (installed as pliant-opencv-dependencies.cmake).
find_dependency(Threads)
find_dependency(OpenCV COMPONENTS core videoio imgcodecs imgproc)
