// Simulated recordings with known ground truth, for tests, examples and benchmarks.
//
// Each scenario runs the core MSM model (double precision, one step per frame interval, as the
// estimators assume) with the true parameters, records every particle every frame and adds
// Gaussian position noise. The truth goes into a separate truth.json document that no
// estimator reads; the recording carries no hint of it.
//
// Every scenario starts with 0.5 s of the object at rest before the tool moves.
// Scenarios
// - foam_press: the optical-flow MSM paper's setup in the image plane (px): a 4 x 8 particle
//   grid at 100 px spacing, bottom row (ids 0..7) fixed on the support, the top-row particle 28
//   under the tool driven 60 px down over 1 s and then held for 3 s. 30 frames/s.
// - block_press: a 3D block (m) of 5 x 5 x 4 particles at 10 mm spacing, bottom layer fixed,
//   the top-centre particle pressed 6 mm down over 1 s and held for 2 s. 30 frames/s.
// - cantilever_strip: a 2D strip (m) of 12 x 3 particles at 10 mm spacing clamped by its two
//   left columns; the tip particle is pulled 20 mm down over 1 s, held 1 s and released, then
//   the strip swings freely for 2 s. 60 frames/s.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pliant/host/recording.hpp"

namespace pliant::host {

struct ScenarioOptions {
  double msm_beta = 0.5;
  double msm_alpha = 1.0;
  double noise = 0.0;        ///< position noise std, as a fraction of the particle spacing
  std::uint64_t seed = 1;
  double rate_hz = 0.0;      ///< frames per second; 0 = the scenario's own rate
};

struct ScenarioResult {
  Recording recording;
  nlohmann::json truth;  ///< {"format": "pliant-truth", "parameters": {...}, "noise_std": ...}
};

/// Names accepted by make_scenario, in a stable order.
std::vector<std::string> scenario_names();

/// Runs a scenario. Throws std::invalid_argument for an unknown name or options out of range
/// (beta outside [0, 1], alpha outside (0, 1], negative noise, rate <= 0 when given).
ScenarioResult make_scenario(const std::string& name, const ScenarioOptions& options);

/// Writes the recording directory and truth.json beside its recording.json.
void write_scenario(const ScenarioResult& scenario, const std::string& directory);

}  // namespace pliant::host
