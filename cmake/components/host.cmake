# Dependencies of pliant's host libraries, found again for a consumer (installed as
# pliant-host-dependencies.cmake). TetGen is linked by its path.
find_dependency(nlohmann_json 3.10)
find_dependency(Ceres 2.0)
find_dependency(spectra 1.0)
