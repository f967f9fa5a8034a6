// A press experiment simulated with the core step: the truth the estimator tests fit.
#pragma once

#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include "msm_fixture.hpp"
#include "pliant/core/observations.hpp"
#include "pliant/core_testing/press.hpp"

namespace pliant::test {

/// Lattice nx x ny (x nz), bottom layer (y = 0) fixed, the top particle near the middle driven
/// down (-y) by `depth` over 1 s and held until `duration_s`, at `rate_hz`, with
/// `steps_per_frame` MSM steps per frame interval (the tool's target moving on between them) and
/// the tool let go after `release_s`. Simulated in Scalar by core_testing::simulate_grid_press;
/// observations get Gaussian noise of std `noise_std` (std::mt19937 from `seed`).
template <int Dim, typename Scalar>
struct PressExperiment {
  ConfigBuilder<Dim, Scalar> builder;
  int tool = 0;
  std::vector<double> times;
  std::vector<Scalar> positions;
  std::vector<DrivenWindow> driven;

  PressExperiment(double beta, double alpha, double noise_std, unsigned seed, int nx = 8, int ny = 4, int nz = 3,
                  double spacing = 100.0, double depth = 60.0, double duration_s = 4.0, double rate_hz = 30.0,
                  double release_s = HUGE_VAL, int steps_per_frame = 1) {
    core_testing::PressGrid grid;
    grid.extents[0] = nx;
    grid.extents[1] = ny;
    grid.extents[2] = nz;
    grid.spacing = spacing;
    grid.support_axis = 1;
    tool = core_testing::grid_top_centre<Dim>(grid);
    builder.fixed = core_testing::grid_support<Dim>(grid);
    builder.drivable = {tool};
    DrivenWindow window;
    window.id = tool;
    window.to_s = release_s;
    driven.push_back(window);

    core_testing::PressMotion motion;
    motion.tool = tool;
    motion.travel[1] = -depth;
    motion.release_s = release_s;
    motion.duration_s = duration_s;
    motion.rate_hz = rate_hz;
    motion.steps_per_frame = steps_per_frame;
    motion.clock = core_testing::PressClock::frame_division;
    core_testing::PositionNoise noise;
    noise.source = core_testing::NoiseSource::normal_mt19937;
    noise.std = noise_std;
    noise.seed = seed;
    MsmParams<Dim, Scalar> params;
    params.msm_beta = static_cast<Scalar>(beta);
    params.msm_alpha = static_cast<Scalar>(alpha);
    core_testing::PressFrames<Scalar> frames;
    (void)core_testing::simulate_grid_press(grid, params, motion, noise, frames);
    times = std::move(frames.times_s);
    positions = std::move(frames.positions);
    // The estimator's rest shape is the first observed frame, as with a camera.
    const int n = core_testing::grid_particle_count<Dim>(grid);
    builder.rest.assign(positions.begin(), positions.begin() + static_cast<std::ptrdiff_t>(n) * Dim);
  }

  ObservationSequence<Dim, Scalar> observations() const {
    ObservationSequence<Dim, Scalar> obs;
    obs.frame_count = static_cast<int>(times.size());
    obs.particle_count = static_cast<int>(builder.rest.size()) / Dim;
    obs.times_s = times.data();
    obs.positions = positions.data();
    obs.driven = driven.data();
    obs.driven_count = static_cast<int>(driven.size());
    return obs;
  }
};

}  // namespace pliant::test
