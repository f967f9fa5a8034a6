// Simulated recordings with known ground truth, for tests, examples, benchmarks and the
// concealed suites that prove `pliant diagnose`.
//
// Each scenario runs the core MSM model (double precision) with the true parameters, records
// every particle every frame and adds Gaussian position noise (the press loop is
// core_testing::simulate_press, shared with the core tests and the benchmarks). The truth goes into a separate
// truth.json document that no estimator reads; the recording carries no hint of it.
//
// By default the generator is the estimators' own model: one MSM step per frame interval,
// clusters of radius 1.5 x the median neighbour distance, every particle seen every frame, no
// extra physics. Options move it away from that, each recorded in truth.json only:
// - effect: one concealed physical effect (see below) switched on in the simulation;
// - substeps: MSM steps per frame interval (the estimators always fit one);
// - cluster_radius_factor: cluster size of the generating model (the estimators use 1.5);
// - occlusion: a share of the (particle, frame) observations removed in contiguous runs;
// - depth and release: the tool's amplitude and whether it lets go at the end.
//
// Every scenario starts with 0.5 s of the object at rest before the tool moves.
// Scenarios
// - foam_press: the optical-flow MSM paper's setup in the image plane (px, y pointing down): a
//   4 x 8 particle grid at 100 px spacing, bottom row (ids 0..7) fixed on the support, the
//   top-row particle 28 under the tool driven 60 px (depth 0.2 of the 300 px height) down over
//   1 s and then held for 3 s. 30 frames/s. With release, the tool lets go after the hold and
//   the recording goes on for 1.5 s more.
// - block_press: a 3D block (m) of 5 x 5 x 4 particles at 10 mm spacing, bottom layer fixed,
//   the top-centre particle pressed 6 mm (depth 0.2) down over 1 s and held for 2 s.
//   30 frames/s. Release as for foam_press. ScenarioOptions::block_grid changes the particle
//   counts (e.g. 10 x 10 x 5 = 500 particles for timing); the tool stays on the top-centre
//   particle (x = nx / 2, y = ny / 2), depth stays a fraction of the height (nz - 1) x 10 mm and
//   the heterogeneity inclusion stays at a quarter of the width, mid-depth, mid-height.
// - cantilever_strip: a 2D strip (m) of 12 x 3 particles at 10 mm spacing clamped by its two
//   left columns; the tip particle is pulled 20 mm (depth 1.0 of the 20 mm height) down over
//   1 s, held 1 s and released, then the strip swings freely for 2 s. 60 frames/s.
// - ring_squeeze: a 2D annulus (m), 22 particles on a 35 mm circle inside 28 on a 45 mm circle,
//   resting on its three lowest outer particles (fixed); the top outer particle is pushed
//   13.5 mm (depth 0.15 of the 90 mm height) down over 1 s, held 1.5 s and released, then
//   1.5 s of free recovery. 30 frames/s.
// - dome_press: a 3D dome (m) of 76 particles on a 10 mm lattice inside a 31 mm hemisphere,
//   its base layer fixed; the apex is pressed 6 mm (depth 0.2 of the 30 mm height) down over
//   1 s, held 1.5 s and released, then 1.5 s of free recovery. 30 frames/s.
//
// Effects (effect_parameters, defaults in brackets; each reduces exactly to no effect at its
// null value, given after the bar):
// - plasticity: yield [0.02], creep [4 /s], max [0.5] | creep 0
// - viscosity: fraction [0.5], tau [0.8 s], damping [0 /s] | fraction 0 and damping 0
// - friction: mu [0.3] on the support plane normal to the direction from the fixed particles
//   into the object | mu inf
// - gravity: g [foam_press 200 px/s^2, block_press 0.02, cantilever_strip 0.01, ring_squeeze
//   0.003, dome_press 0.08 m/s^2: a sag visible before the tool moves; scaled by the square of
//   the step rate when rate or substeps change], tilt [0 degrees from "down" toward +x]; "down"
//   is +y in foam_press's image plane, -y in the other 2D scenes, -z in 3D. The recording's
//   gravity key stays absent | g 0
// - heterogeneity: ratio [0.3] = msm_beta inside the region / msm_beta elsewhere, region
//   [inclusion] (left, right or inclusion: a ball of radius [2] spacings in the object) | ratio 1
// - stiffening: k [10]: cluster beta / (1 + k |strain|) | k 0
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pliant/host/recording.hpp"

namespace pliant::host {

struct ScenarioOptions {
  double msm_beta = 0.5;
  double msm_alpha = 1.0;
  double noise = 0.0;  ///< position noise std, as a fraction of the particle spacing
  std::uint64_t seed = 1;
  double rate_hz = 0.0;  ///< frames per second; 0 = the scenario's own rate
  /// Concealed effect: "" or "none" = no effect, else one of effect_names().
  std::string effect;
  std::map<std::string, double> effect_parameters;   ///< numeric parameters by name
  std::map<std::string, std::string> effect_labels;  ///< named settings (heterogeneity region)
  int substeps = 1;                                  ///< MSM steps per frame interval, 1..64
  double cluster_radius_factor = 1.5;                ///< generator's cluster radius / median neighbour distance
  double occlusion = 0.0;                            ///< share of (particle, frame) observations removed, [0, 0.5]
  double depth = 0.0;                                ///< tool amplitude / object height; 0 = the scenario's own
  bool release = false;                              ///< foam_press, block_press: the tool lets go for the last 1.5 s
  /// block_press only: particles along x, y and z (z up, layer 0 fixed); each 2..64. Another
  /// scenario refuses a grid other than the default.
  struct BlockGrid {
    int nx = 5, ny = 5, nz = 4;
  } block_grid;
};

struct ScenarioResult {
  Recording recording;
  nlohmann::json truth;  ///< {"format": "pliant-truth", "parameters": {...}, "effect": ..., ...}
};

/// Names accepted by make_scenario, in a stable order.
std::vector<std::string> scenario_names();

/// Effect names accepted in ScenarioOptions::effect, in a stable order (without "none").
std::vector<std::string> effect_names();

/// One line: every effect with its parameters and defaults, "name:param=default,...; ...".
std::string describe_effects();

/// Reads "NAME" or "NAME:param=value,param=value" (the --effect argument) into options.effect,
/// effect_parameters (values that read as numbers, "inf" included) and effect_labels (the
/// rest). Throws std::invalid_argument (one line) for a malformed text; names are checked by
/// make_scenario.
void parse_effect_argument(const std::string& text, ScenarioOptions& options);

/// Runs a scenario. Throws std::invalid_argument (one line naming the option) for an unknown
/// name or options out of range (beta outside [0, 1], alpha outside (0, 1], negative noise,
/// rate <= 0 when given, unknown effect or effect parameter, substeps outside 1..64, cluster
/// radius outside [1, 4], occlusion outside [0, 0.5], depth outside [0, 2], block_grid outside
/// 2..64 per axis or not the default outside block_press).
ScenarioResult make_scenario(const std::string& name, const ScenarioOptions& options);

/// Writes the recording directory and truth.json beside its recording.json.
void write_scenario(const ScenarioResult& scenario, const std::string& directory);

namespace detail {

/// What the effect catalogue needs to know about a scenario's object.
struct EffectGeometry {
  int dimension = 2;
  double spacing = 1.0;
  std::vector<double> rest;  ///< particle-major
  std::vector<int> fixed;
  std::vector<double> down;            ///< unit vector: where "down" points in this frame
  std::vector<double> support_normal;  ///< unit vector from the fixed particles into the object
  std::vector<double> inclusion_centre;
  double default_gravity = 0.0;  ///< g for the gravity effect when not given
};

/// One effect resolved against a scenario: every MsmParams knob it sets, with defaults filled.
struct EffectPhysics {
  std::string name = "none";
  std::map<std::string, double> parameters;   ///< all numeric parameters, defaults filled
  std::map<std::string, std::string> labels;  ///< all named settings, defaults filled
  std::vector<double> gravity;                ///< dimension components
  double velocity_damping = 0.0;
  double plastic_yield = 0.0, plastic_creep = 0.0, plastic_max = 1.0;
  double relaxation_fraction = 0.0, relaxation_time_s = 1.0;
  double stiffening = 0.0;
  double support_friction = std::numeric_limits<double>::infinity();  ///< infinity = pinned
  std::vector<double> support_normal;
  double region_beta_ratio = 1.0;                     ///< heterogeneity: beta inside / beta outside
  std::function<bool(const double*)> in_region;       ///< heterogeneity: a rest point in the region
  nlohmann::json details = nlohmann::json::object();  ///< derived values for truth.json
};

/// Validates options.effect and its parameters and fills in defaults. Throws
/// std::invalid_argument listing the valid names.
EffectPhysics resolve_effect(const ScenarioOptions& options, const EffectGeometry& geometry);

/// How far an effect moved the recording: {"rms": per coordinate, "max": largest particle
/// offset, "rms_over_noise": rms / noise_std (null without noise)}, from two runs of one scene
/// with the same noise, before occlusion.
nlohmann::json effect_size(const Recording& with, const Recording& without, double noise_std);

/// Marks round(fraction x frames x particles) observations unobserved (NaN), in contiguous runs
/// of frames, never in frame 0 and never a driven particle inside its driven window. Returns
/// the number removed.
long occlude(Recording& recording, double fraction, std::uint64_t seed);

}  // namespace detail
}  // namespace pliant::host
