// Compiled with -fno-exceptions -fno-rtti (CMakeLists.txt): the press headers build as core code.
#include "pliant/core_testing/press.hpp"

namespace pliant::core_testing {

template Status simulate_grid_press<2, float, float>(const PressGrid&, const MsmParams<2, float>&, const PressMotion&,
                                                     const PositionNoise&, PressFrames<float>&);
template Status simulate_grid_press<3, double, double>(const PressGrid&, const MsmParams<3, double>&,
                                                       const PressMotion&, const PositionNoise&, PressFrames<double>&);

}  // namespace pliant::core_testing
