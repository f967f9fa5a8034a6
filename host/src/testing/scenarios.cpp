#include "pliant/host/scenarios.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <utility>

#include "pliant/core_testing/press.hpp"
#include "pliant/host/msm_setup.hpp"

namespace pliant::host {
namespace {

// Geometry and motion of one scenario, before simulation.
struct ScenarioPlan {
  int dimension = 2;
  std::string length_unit = "m";
  double spacing = 1.0;
  std::vector<double> rest;  // particle-major
  std::vector<int> fixed;
  int tool = 0;                 // driven particle
  double release_s = HUGE_VAL;  // the tool lets go after this time
  double duration_s = 0;
  double rate_hz = 30;
  std::vector<double> tool_direction;  // unit direction of the tool's travel
  double height = 1.0;                 // object size along the tool's travel, for --depth
  double travel = 0.0;                 // the scenario's own tool travel (length unit)
  std::string object;
  std::vector<double> down;            // where "down" points in the scenario's frame
  std::vector<double> support_normal;  // from the fixed particles into the object
  std::vector<double> inclusion_centre;
  double gravity_g = 0.0;  // default g of the gravity effect at the scenario's own rate
};

// Every scenario films the object still for this long before the tool starts to move, as a
// robot camera does while the arm approaches.
constexpr double kLeadIn_s = 0.5;
// With a release, the recording goes on this long after the tool lets go.
constexpr double kReleaseTail_s = 1.5;

// Default g of the gravity effect per scenario at its own frame rate (length unit / s^2): the
// object (msm_beta 0.5) visibly settles within the 0.5 s before the tool moves (foam, block and
// dome by about 2 % of their height, the strip's tip by 1 mm, the ring by 0.4 mm), and the strip
// and the ring keep sinking after the release. MSM clusters give way to a body force far more
// than real foam does, hence the small values.
constexpr double kGravityFoam = 200.0;
constexpr double kGravityBlock = 0.02;
constexpr double kGravityCantilever = 0.01;
constexpr double kGravityRing = 0.003;
constexpr double kGravityDome = 0.08;

// A grid object from core_testing's press grid (the one the core tests and benchmarks press):
// rest shape, the support layer as fixed ids and the tool on the top-centre particle.
template <int Dim>
void place_grid(const core_testing::PressGrid& grid, ScenarioPlan& plan) {
  plan.rest = core_testing::grid_rest<Dim, double>(grid);
  const std::vector<std::uint8_t> support = core_testing::grid_support<Dim>(grid);
  for (std::size_t i = 0; i < support.size(); ++i) {
    if (support[i] != 0) plan.fixed.push_back(static_cast<int>(i));
  }
  plan.tool = core_testing::grid_top_centre<Dim>(grid);
}

ScenarioPlan foam_press(bool release) {
  ScenarioPlan plan;
  plan.dimension = 2;
  plan.length_unit = "px";
  plan.spacing = 100.0;
  // Image coordinates: y grows downward; row 0 is the bottom row on the support.
  core_testing::PressGrid grid;
  grid.extents[0] = 8;
  grid.extents[1] = 4;
  grid.spacing = plan.spacing;
  grid.origin[0] = 560.0;
  grid.origin[1] = 840.0;
  grid.sign[1] = -1.0;
  grid.support_axis = 1;
  place_grid<2>(grid, plan);  // the tool on particle 28
  plan.duration_s = kLeadIn_s + 4.0;
  if (release) {
    plan.release_s = plan.duration_s;
    plan.duration_s += kReleaseTail_s;
  }
  plan.rate_hz = 30.0;
  plan.tool_direction = {0.0, 1.0};
  plan.height = 300.0;
  plan.travel = 60.0;
  plan.object = "simulated foam block pressed by a tool, image plane";
  plan.down = {0.0, 1.0};
  plan.support_normal = {0.0, -1.0};
  plan.inclusion_centre = {960.0, 690.0};
  plan.gravity_g = kGravityFoam;
  return plan;
}

ScenarioPlan block_press(bool release, const ScenarioOptions::BlockGrid& grid) {
  ScenarioPlan plan;
  plan.dimension = 3;
  plan.length_unit = "m";
  plan.spacing = 0.01;
  const int nx = grid.nx;
  const int ny = grid.ny;
  const int nz = grid.nz;
  core_testing::PressGrid block;
  block.extents[0] = nx;
  block.extents[1] = ny;
  block.extents[2] = nz;
  block.spacing = plan.spacing;
  block.support_axis = 2;
  place_grid<3>(block, plan);  // the tool on the top-centre particle
  plan.duration_s = kLeadIn_s + 3.0;
  if (release) {
    plan.release_s = plan.duration_s;
    plan.duration_s += kReleaseTail_s;
  }
  plan.rate_hz = 30.0;
  plan.tool_direction = {0.0, 0.0, -1.0};
  // For the default 5 x 5 x 4 grid these are exactly 0.03, 0.006 and {0.01, 0.02, 0.015}.
  plan.height = 0.01 * (nz - 1);
  plan.travel = 0.2 * plan.height;
  plan.object = "simulated 3D block pressed from above";
  plan.down = {0.0, 0.0, -1.0};
  plan.support_normal = {0.0, 0.0, 1.0};
  plan.inclusion_centre = {0.01 * (nx - 1) / 4, 0.01 * (ny - 1) / 2, 0.01 * (nz - 1) / 2};
  plan.gravity_g = kGravityBlock;
  return plan;
}

ScenarioPlan cantilever_strip() {
  ScenarioPlan plan;
  plan.dimension = 2;
  plan.length_unit = "m";
  plan.spacing = 0.01;
  const int cols = 12;
  const int rows = 3;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      plan.rest.push_back(0.01 * c);
      plan.rest.push_back(0.01 * r);
      if (c < 2) plan.fixed.push_back(r * cols + c);
    }
  }
  plan.tool = 1 * cols + (cols - 1);
  plan.release_s = kLeadIn_s + 2.0;
  plan.duration_s = kLeadIn_s + 4.0;
  plan.rate_hz = 60.0;
  plan.tool_direction = {0.0, -1.0};
  plan.height = 0.02;
  plan.travel = 0.02;
  plan.object = "simulated clamped strip, tip pulled down and released";
  plan.down = {0.0, -1.0};
  // The clamp holds the strip's left end: its plane is vertical, the strip lies toward +x.
  plan.support_normal = {1.0, 0.0};
  plan.inclusion_centre = {0.06, 0.01};
  plan.gravity_g = kGravityCantilever;
  return plan;
}

// Two staggered rings at about one spacing apart along and across, standing on the support.
ScenarioPlan ring_squeeze() {
  ScenarioPlan plan;
  plan.dimension = 2;
  plan.length_unit = "m";
  plan.spacing = 0.01;
  const double pi = std::acos(-1.0);
  const double centre_y = 0.045;
  struct Ring {
    int count;
    double radius;
  };
  const Ring rings[] = {{22, 0.035}, {28, 0.045}};
  for (const Ring& ring : rings) {
    for (int i = 0; i < ring.count; ++i) {
      // Particle 0 of each ring at the bottom; angles counter-clockwise.
      const double angle = -0.5 * pi + 2.0 * pi * i / ring.count;
      plan.rest.push_back(ring.radius * std::cos(angle));
      plan.rest.push_back(centre_y + ring.radius * std::sin(angle));
    }
  }
  const int outer = rings[0].count;
  plan.fixed = {outer, outer + 1, outer + rings[1].count - 1};
  std::sort(plan.fixed.begin(), plan.fixed.end());
  plan.tool = outer + rings[1].count / 2;  // the top of the outer ring
  plan.release_s = kLeadIn_s + 2.5;
  plan.duration_s = kLeadIn_s + 4.0;
  plan.rate_hz = 30.0;
  plan.tool_direction = {0.0, -1.0};
  plan.height = 0.09;
  plan.travel = 0.0135;
  plan.object = "simulated ring standing on a support, squeezed from the top and released";
  plan.down = {0.0, -1.0};
  plan.support_normal = {0.0, 1.0};
  plan.inclusion_centre = {0.04, centre_y};  // in the right-hand wall
  plan.gravity_g = kGravityRing;
  return plan;
}

// Lattice points inside a hemisphere of radius sqrt(9.5) spacings on its base.
ScenarioPlan dome_press() {
  ScenarioPlan plan;
  plan.dimension = 3;
  plan.length_unit = "m";
  plan.spacing = 0.01;
  for (int z = 0; z <= 3; ++z) {
    for (int y = -3; y <= 3; ++y) {
      for (int x = -3; x <= 3; ++x) {
        if (2 * (x * x + y * y + z * z) > 19) continue;
        if (z == 0) plan.fixed.push_back(static_cast<int>(plan.rest.size() / 3));
        plan.rest.push_back(0.01 * x);
        plan.rest.push_back(0.01 * y);
        plan.rest.push_back(0.01 * z);
      }
    }
  }
  plan.tool = static_cast<int>(plan.rest.size() / 3) - 1;  // the apex (0, 0, 3)
  plan.release_s = kLeadIn_s + 2.5;
  plan.duration_s = kLeadIn_s + 4.0;
  plan.rate_hz = 30.0;
  plan.tool_direction = {0.0, 0.0, -1.0};
  plan.height = 0.03;
  plan.travel = 0.006;
  plan.object = "simulated 3D dome on a support, pressed at its apex and released";
  plan.down = {0.0, 0.0, -1.0};
  plan.support_normal = {0.0, 0.0, 1.0};
  plan.inclusion_centre = {-0.01, 0.0, 0.01};
  plan.gravity_g = kGravityDome;
  return plan;
}

ScenarioPlan plan_for(const std::string& name, const ScenarioOptions& options) {
  const bool release = options.release;
  if (name == "foam_press") return foam_press(release);
  if (name == "block_press") return block_press(release, options.block_grid);
  if (name == "cantilever_strip") return cantilever_strip();
  if (name == "ring_squeeze") return ring_squeeze();
  if (name == "dome_press") return dome_press();
  std::string known;
  for (const std::string& scenario : scenario_names()) known += (known.empty() ? "" : ", ") + scenario;
  throw std::invalid_argument("unknown scenario '" + name + "' (known: " + known + ")");
}

template <int Dim>
void simulate(const ScenarioPlan& plan, const ScenarioOptions& options, detail::EffectPhysics& effect,
              Recording& recording) {
  MsmSetupOptions setup;
  setup.clusters.radius_factor = options.cluster_radius_factor;
  auto model = build_msm_model<Dim>(recording, setup);
  MsmParams<Dim, double> params = base_params<Dim>(recording, options.msm_alpha);
  params.msm_beta = options.msm_beta;
  // The concealed effect acts on the simulation only; the recording never declares it.
  for (int d = 0; d < Dim; ++d) params.gravity(d) = effect.gravity[static_cast<std::size_t>(d)];
  params.velocity_damping = effect.velocity_damping;
  params.plastic_yield = effect.plastic_yield;
  params.plastic_creep = effect.plastic_creep;
  params.plastic_max = effect.plastic_max;
  params.relaxation_fraction = effect.relaxation_fraction;
  params.relaxation_time_s = effect.relaxation_time_s;
  params.stiffening = effect.stiffening;
  params.support_friction = effect.support_friction;
  for (int d = 0; d < Dim; ++d) params.support_normal(d) = effect.support_normal[static_cast<std::size_t>(d)];
  std::vector<double> cluster_beta;
  if (effect.in_region) {
    int inside = 0;
    for (int c = 0; c < model->model.cluster_count; ++c) {
      const Eigen::Matrix<double, Dim, 1> centre = model->model.cluster_rest_centroid[c];
      const bool in = effect.in_region(centre.data());
      inside += in ? 1 : 0;
      cluster_beta.push_back(in ? options.msm_beta * effect.region_beta_ratio : options.msm_beta);
    }
    params.cluster_beta = cluster_beta.data();
    effect.details["region_clusters"] = inside;
    effect.details["cluster_count"] = model->model.cluster_count;
  }

  // The press itself: core_testing's, shared with the core tests and the benchmarks.
  core_testing::PressMotion motion;
  motion.tool = plan.tool;
  const double travel = options.depth > 0.0 ? options.depth * plan.height : plan.travel;
  for (int d = 0; d < Dim; ++d) motion.travel[d] = plan.tool_direction[static_cast<std::size_t>(d)] * travel;
  motion.lead_in_s = kLeadIn_s;
  motion.ramp_s = 1.0;
  motion.release_s = plan.release_s;
  motion.duration_s = plan.duration_s;
  motion.rate_hz = plan.rate_hz;
  motion.steps_per_frame = options.substeps;
  motion.clock = core_testing::PressClock::step_count;
  core_testing::PositionNoise noise;
  noise.source = core_testing::NoiseSource::normal_mt19937_64;
  noise.std = options.noise * plan.spacing;
  noise.seed = options.seed;
  core_testing::PressFrames<double> frames;
  require_ok(core_testing::simulate_press(model->model, params, motion, noise, frames), "scenario step");
  recording.frame_times_s = std::move(frames.times_s);
  recording.positions = std::move(frames.positions);
}

void check_options(const ScenarioOptions& options) {
  if (!(options.msm_beta >= 0.0 && options.msm_beta <= 1.0)) throw std::invalid_argument("--beta must be in [0, 1]");
  if (!(options.msm_alpha > 0.0 && options.msm_alpha <= 1.0)) throw std::invalid_argument("--alpha must be in (0, 1]");
  if (!(options.noise >= 0.0) || !std::isfinite(options.noise)) throw std::invalid_argument("--noise must be >= 0");
  if (options.rate_hz != 0.0 && !(options.rate_hz > 0.0 && std::isfinite(options.rate_hz))) {
    throw std::invalid_argument("--rate must be > 0");
  }
  if (options.substeps < 1 || options.substeps > 64) throw std::invalid_argument("--substeps must be in 1..64");
  if (!(options.cluster_radius_factor >= 1.0 && options.cluster_radius_factor <= 4.0)) {
    throw std::invalid_argument("--cluster-radius must be in [1, 4]");
  }
  if (!(options.occlusion >= 0.0 && options.occlusion <= 0.5))
    throw std::invalid_argument("--occlusion must be in [0, 0.5]");
  if (!(options.depth >= 0.0 && options.depth <= 2.0)) throw std::invalid_argument("--depth must be in (0, 2]");
  for (const int count : {options.block_grid.nx, options.block_grid.ny, options.block_grid.nz}) {
    if (count < 2 || count > 64) throw std::invalid_argument("block_grid must be 2..64 particles along each axis");
  }
}

}  // namespace

std::vector<std::string> scenario_names() {
  return {"foam_press", "block_press", "cantilever_strip", "ring_squeeze", "dome_press"};
}

ScenarioResult make_scenario(const std::string& name, const ScenarioOptions& options) {
  check_options(options);
  const ScenarioOptions::BlockGrid grid = options.block_grid;
  const ScenarioOptions::BlockGrid default_grid;
  const bool default_size = grid.nx == default_grid.nx && grid.ny == default_grid.ny && grid.nz == default_grid.nz;
  if (name != "block_press" && !default_size) throw std::invalid_argument("block_grid applies to block_press only");
  ScenarioPlan plan = plan_for(name, options);
  const double own_rate_hz = plan.rate_hz;
  if (options.rate_hz > 0.0) plan.rate_hz = options.rate_hz;

  detail::EffectGeometry geometry;
  geometry.dimension = plan.dimension;
  geometry.spacing = plan.spacing;
  geometry.rest = plan.rest;
  geometry.fixed = plan.fixed;
  geometry.down = plan.down;
  geometry.support_normal = plan.support_normal;
  geometry.inclusion_centre = plan.inclusion_centre;
  // MSM's static response to a body force scales with g dt^2, so the default g follows the
  // step rate: the default sag is the same at any frame rate and substep count.
  const double step_ratio = plan.rate_hz * options.substeps / own_rate_hz;
  geometry.default_gravity = plan.gravity_g * step_ratio * step_ratio;
  detail::EffectPhysics effect = detail::resolve_effect(options, geometry);

  ScenarioResult result;
  Recording& rec = result.recording;
  rec.name = name;
  rec.dimension = plan.dimension;
  rec.length_unit = plan.length_unit;
  rec.particle_count = static_cast<int>(plan.rest.size()) / plan.dimension;
  rec.masses.assign(static_cast<std::size_t>(rec.particle_count), 1.0);
  rec.fixed = plan.fixed;
  DrivenWindow window;
  window.id = plan.tool;
  if (std::isfinite(plan.release_s)) window.to_s = plan.release_s;
  rec.driven.push_back(window);
  rec.files["particles"] = "particles.csv";
  rec.meta = {{"object", plan.object}, {"generator", "pliant simulate " + name}};
  rec.rest_positions = plan.rest;
  Recording twin = rec;  // the same scene without the effect, to measure the effect's size
  auto run = [&](detail::EffectPhysics& physics, Recording& target) {
    if (plan.dimension == 2) {
      simulate<2>(plan, options, physics, target);
    } else {
      simulate<3>(plan, options, physics, target);
    }
  };
  run(effect, rec);
  nlohmann::json effect_size = nullptr;
  if (effect.name != "none") {
    detail::EffectPhysics none;
    none.gravity.assign(static_cast<std::size_t>(plan.dimension), 0.0);
    none.support_normal = plan.support_normal;
    run(none, twin);
    effect_size = detail::effect_size(rec, twin, options.noise * plan.spacing);
  }
  // The recording's rest shape is its first (noisy) frame, as a camera would see it.
  rec.rest_positions.assign(rec.positions.begin(),
                            rec.positions.begin() + static_cast<std::ptrdiff_t>(rec.particle_count * rec.dimension));
  const long occluded = detail::occlude(rec, options.occlusion, options.seed);

  nlohmann::json effect_parameters = nlohmann::json::object();
  for (const auto& [key, value] : effect.parameters) {
    // JSON has no infinity: an infinite mu (the pinned support) is written as the string "inf".
    effect_parameters[key] = std::isfinite(value) ? nlohmann::json(value) : nlohmann::json("inf");
  }
  for (const auto& [key, value] : effect.labels) effect_parameters[key] = value;
  const double travel = options.depth > 0.0 ? options.depth * plan.height : plan.travel;
  result.truth = {
      {"format", "pliant-truth"},
      {"version", 1},
      {"scenario", name},
      {"model", "msm"},
      {"parameters", {{"msm_beta", options.msm_beta}, {"msm_alpha", options.msm_alpha}}},
      {"effect", effect.name},
      {"effect_parameters", effect_parameters},
      {"effect_details", effect.details},
      // The effect against the same scene without it: rms per coordinate, largest particle offset.
      {"effect_size", effect_size},
      {"steps_per_frame", options.substeps},
      {"cluster_radius_factor", options.cluster_radius_factor},
      {"rate_hz", plan.rate_hz},
      {"depth", travel / plan.height},
      {"tool_travel", travel},
      {"release_s", std::isfinite(plan.release_s) ? nlohmann::json(plan.release_s) : nlohmann::json(nullptr)},
      {"noise_fraction_of_spacing", options.noise},
      {"noise_std", options.noise * plan.spacing},
      {"occlusion", options.occlusion},
      {"occluded_observations", occluded},
      {"spacing", plan.spacing},
      {"seed", options.seed},
  };
  return result;
}

void write_scenario(const ScenarioResult& scenario, const std::string& directory) {
  write_recording(scenario.recording, directory);
  const std::filesystem::path path = std::filesystem::path(directory) / "truth.json";
  std::ofstream out(path);
  out << scenario.truth.dump(2) << '\n';
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace pliant::host
