// A press experiment simulated with the core step: the truth the estimator tests fit.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "msm_fixture.hpp"
#include "pliant/core/observations.hpp"

namespace pliant::test {

/// Lattice nx x ny (x nz), bottom layer fixed, the top particle near the middle driven down by
/// `depth` over 1 s and held until `duration_s`, at `rate_hz`, with `steps_per_frame` MSM steps
/// per frame interval (the tool's target moving on between them). Observations get Gaussian noise.
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
    builder.rest = lattice<Dim, Scalar>(nx, ny, nz, spacing);
    const int n = static_cast<int>(builder.rest.size()) / Dim;
    builder.fixed.assign(static_cast<std::size_t>(n), 0);
    const int layers = Dim == 3 ? nz : 1;
    for (int z = 0; z < layers; ++z) {
      for (int x = 0; x < nx; ++x) builder.fixed[static_cast<std::size_t>(z * ny * nx + x)] = 1;
    }
    tool = ((layers / 2) * ny + ny - 1) * nx + nx / 2;
    builder.drivable = {tool};
    DrivenWindow window;
    window.id = tool;
    window.to_s = release_s;
    driven.push_back(window);

    MsmFixture<Dim, Scalar> truth(builder.config());
    MsmParams<Dim, Scalar> params;
    params.msm_beta = static_cast<Scalar>(beta);
    params.msm_alpha = static_cast<Scalar>(alpha);
    std::mt19937 rng(seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    const int frames = static_cast<int>(std::lround(duration_s * rate_hz)) + 1;
    auto record = [&](double t) {
      times.push_back(t);
      for (int i = 0; i < n; ++i) {
        for (int d = 0; d < Dim; ++d) {
          positions.push_back(
              static_cast<Scalar>(static_cast<double>(truth.state.position[i](d)) + noise_std * normal(rng)));
        }
      }
    };
    record(0.0);
    Eigen::Matrix<Scalar, Dim, 1> target = truth.model.rest[tool];
    MsmStepInput<Dim, Scalar> in;
    in.dt = static_cast<Scalar>(1.0 / (rate_hz * steps_per_frame));
    for (int k = 1; k < frames; ++k) {
      for (int j = 1; j <= steps_per_frame; ++j) {
        const double t = (k - 1 + static_cast<double>(j) / steps_per_frame) / rate_hz;
        target(1) = static_cast<Scalar>(static_cast<double>(truth.model.rest[tool](1)) - depth * std::min(1.0, t));
        in.driven = {&tool, &target, k / rate_hz <= release_s ? 1 : 0};
        (void)msm_step(truth.model, params, in, truth.state);
      }
      record(k / rate_hz);
    }
    // The estimator's rest shape is the first observed frame, as with a camera.
    for (std::size_t i = 0; i < builder.rest.size(); ++i) builder.rest[i] = positions[i];
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
