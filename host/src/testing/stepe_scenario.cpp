// The simulated foam-block indentation of stepe_scenario.hpp.
#include "pliant/host/fem/stepe_scenario.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_solver.hpp"

namespace pliant::host::fem {
namespace {

constexpr double kPi = 3.14159265358979323846;
std::size_t uz(int i) { return static_cast<std::size_t>(i); }
Eigen::Index ix(int i) { return static_cast<Eigen::Index>(i); }

void check(const StepeScenarioOptions& o) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("make_stepe_scenario: " + what); };
  if (!(o.block_size_m.minCoeff() > 0) || !o.block_size_m.allFinite()) fail("block sizes must be positive");
  for (int a = 0; a < 3; ++a) {
    if (o.cells[uz(a)] < 1 || o.generation_refinement[uz(a)] < 1) fail("cells and refinements must be >= 1");
  }
  if (o.cells[0] % 2 != 0 || o.cells[1] % 2 != 0) fail("cells in x and y must be even (a top-centre node)");
  if (o.probe_cells < 1 || 2 * o.probe_cells > std::min(o.cells[0], o.cells[1]) - 2) {
    fail("probe_cells must be >= 1 and leave a free margin around the footprint");
  }
  if (!(o.youngs_modulus_pa > 0) || !(o.poisson_ratio > -1 && o.poisson_ratio < 0.5) || !(o.density_kg_m3 > 0)) {
    fail("bad material");
  }
  if (o.ramp_frames < 1 || o.hold_frames < 0 || !(o.frame_interval_s > 0)) fail("bad frame counts or interval");
  if (!(o.position_noise_m >= 0) || !(o.force_noise_n >= 0) || o.outlier_count < 0 || !(o.outlier_offset_m >= 0)) {
    fail("noise and outlier settings must be >= 0");
  }
  if (!(std::abs(o.tilt_deg) < 80)) fail("tilt_deg must be within +-80");
  if (o.control == ProbeControl::force && !(std::isfinite(o.peak_force_n))) fail("peak_force_n must be finite");
  if (o.control == ProbeControl::displacement && !(o.depth_m >= 0 && o.depth_m < o.block_size_m.z())) {
    fail("depth_m must be in [0, block height)");
  }
  if (o.declare_probe_driven && o.control != ProbeControl::displacement) {
    fail("declare_probe_driven needs displacement control");
  }
}

// Grid id of point (i, j, k) in a box mesh with `cells`, x fastest (fem_box_mesh.hpp).
int grid_id(const std::array<int, 3>& cells, int i, int j, int k) {
  return (k * (cells[1] + 1) + j) * (cells[0] + 1) + i;
}

// Consistent nodal weights of a uniform traction over the triangles of the top face whose three
// corners are all in `inside` (weights sum to 1).
std::vector<std::pair<int, double>> pressure_weights(const FemModel& model, const std::vector<char>& inside) {
  std::vector<double> weight(uz(model.node_count()), 0.0);
  const Eigen::VectorXd& rest = model.rest_position_m();
  double total = 0;
  for (const auto& tet : model.elements()) {
    for (int skip = 0; skip < 4; ++skip) {
      int corner[3];
      int k = 0;
      for (int q = 0; q < 4; ++q) {
        if (q != skip) corner[k++] = tet[uz(q)];
      }
      if (inside[uz(corner[0])] == 0 || inside[uz(corner[1])] == 0 || inside[uz(corner[2])] == 0) continue;
      const Eigen::Vector3d p0 = rest.segment<3>(3 * ix(corner[0]));
      const Eigen::Vector3d p1 = rest.segment<3>(3 * ix(corner[1]));
      const Eigen::Vector3d p2 = rest.segment<3>(3 * ix(corner[2]));
      const double area = 0.5 * (p1 - p0).cross(p2 - p0).norm();
      for (int c : corner) weight[uz(c)] += area / 3.0;
      total += area;
    }
  }
  std::vector<std::pair<int, double>> out;
  for (int i = 0; i < model.node_count(); ++i) {
    if (weight[uz(i)] > 0) out.emplace_back(i, weight[uz(i)] / total);
  }
  return out;
}

nlohmann::json vector_json(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

// Frame 0 at rest, then ramp_frames ramping up, then hold_frames at the peak.
int frame_count(const StepeScenarioOptions& o) { return 1 + o.ramp_frames + o.hold_frames; }

// The estimation mesh (the recording's), the generation mesh (cells x generation_refinement) and
// which generation node each estimation node is.
struct ScenarioMeshes {
  std::array<int, 3> fine_cells{};
  TetMesh coarse;            // estimation mesh, mirrored Kuhn
  TetMesh fine;              // generation mesh, generation_split
  std::vector<int> to_fine;  // estimation node -> generation node (same rest point)
};

ScenarioMeshes make_meshes(const StepeScenarioOptions& o) {
  ScenarioMeshes m;
  m.fine_cells = {o.cells[0] * o.generation_refinement[0], o.cells[1] * o.generation_refinement[1],
                  o.cells[2] * o.generation_refinement[2]};
  m.coarse = make_box_tet_mesh(o.block_size_m, o.cells, BoxSplit::mirrored_kuhn);
  m.fine = make_box_tet_mesh(o.block_size_m, m.fine_cells, o.generation_split);
  m.to_fine.resize(uz(m.coarse.point_count()));
  for (int k = 0; k <= o.cells[2]; ++k) {
    for (int j = 0; j <= o.cells[1]; ++j) {
      for (int i = 0; i <= o.cells[0]; ++i) {
        const int c = grid_id(o.cells, i, j, k);
        const int f = grid_id(m.fine_cells, i * o.generation_refinement[0], j * o.generation_refinement[1],
                              k * o.generation_refinement[2]);
        for (int a = 0; a < 3; ++a) {
          if (std::abs(m.coarse.points[uz(3 * c + a)] - m.fine.points[uz(3 * f + a)]) > 1e-12) {
            throw std::logic_error("make_stepe_scenario: estimation and generation grids disagree");
          }
        }
        m.to_fine[uz(c)] = f;
      }
    }
  }
  return m;
}

FemMaterial scenario_material(const StepeScenarioOptions& o) {
  FemMaterial material;
  material.youngs_modulus_pa = o.youngs_modulus_pa;
  material.poisson_ratio = o.poisson_ratio;
  material.density_kg_m3 = o.density_kg_m3;
  return material;
}

// Where the probe presses, and the faces of both meshes that matter. Node lists are ascending.
struct ProbeLayout {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // top-centre point (m): the torque reference
  double half_x = 0;                                 // footprint half-widths (m)
  double half_y = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit: -z tilted toward +x by tilt_deg
  std::vector<int> fine_probe;                          // generation nodes under the footprint
  std::vector<char> fine_inside;                        // per generation node: 1 under the footprint
  std::vector<int> fine_bottom;                         // generation nodes on the table (fixed)
  std::vector<int> probe;                               // estimation nodes under it: wrench.applied_to
  std::vector<int> top_nodes;                           // estimation nodes of the top face
  std::vector<int> coarse_bottom;                       // estimation nodes on the table (fixed)
};

ProbeLayout layout_probe(const StepeScenarioOptions& o, const ScenarioMeshes& meshes) {
  ProbeLayout p;
  const double top = o.block_size_m.z();
  const double tolerance = 1e-9 * o.block_size_m.norm();
  p.centre = Eigen::Vector3d(0.5 * o.block_size_m.x(), 0.5 * o.block_size_m.y(), top);
  p.half_x = o.probe_cells * o.block_size_m.x() / o.cells[0];
  p.half_y = o.probe_cells * o.block_size_m.y() / o.cells[1];
  auto in_footprint = [&](const TetMesh& mesh, int i) {
    const double x = mesh.points[uz(3 * i)];
    const double y = mesh.points[uz(3 * i + 1)];
    return std::abs(x - p.centre.x()) <= p.half_x + tolerance && std::abs(y - p.centre.y()) <= p.half_y + tolerance;
  };
  p.fine_inside.assign(uz(meshes.fine.point_count()), 0);
  for (int i : points_on_plane(meshes.fine, 2, top, tolerance)) {
    if (in_footprint(meshes.fine, i)) {
      p.fine_probe.push_back(i);
      p.fine_inside[uz(i)] = 1;
    }
  }
  for (int i : points_on_plane(meshes.coarse, 2, top, tolerance)) {
    p.top_nodes.push_back(i);
    if (in_footprint(meshes.coarse, i)) p.probe.push_back(i);
  }
  p.fine_bottom = points_on_plane(meshes.fine, 2, 0.0, tolerance);
  p.coarse_bottom = points_on_plane(meshes.coarse, 2, 0.0, tolerance);
  std::sort(p.coarse_bottom.begin(), p.coarse_bottom.end());
  const double tilt = o.tilt_deg * kPi / 180.0;
  p.direction = Eigen::Vector3d(std::sin(tilt), 0.0, -std::cos(tilt));
  return p;
}

// The noise-free truth of every frame on the generation mesh.
struct GeneratedFrames {
  std::vector<Eigen::VectorXd> positions;  // 3 per generation node (m)
  std::vector<Eigen::Vector3d> force_n;    // probe on block
  std::vector<Eigen::Vector3d> torque_nm;  // about the footprint centre, lever arms at rest
  std::vector<double> travel_m;            // footprint's mean displacement along the probe direction
  int newton_iterations = 0;
};

// What the probe does to the generation model: force control loads the footprint nodes by
// `weights` (summing to 1), displacement control drives them.
struct ProbePress {
  const StepeScenarioOptions& o;
  const FemModel& model;
  const ProbeLayout& probe;
  bool force_control = false;
  std::vector<std::pair<int, double>> weights;  // (generation node, share of the force)
  std::vector<int> driven;                      // displacement control: the footprint nodes
};

ProbePress make_probe_press(const StepeScenarioOptions& o, const FemModel& model, const ProbeLayout& probe) {
  ProbePress press{o, model, probe, o.control == ProbeControl::force, {}, {}};
  if (o.equal_nodal_shares) {
    for (int node : probe.fine_probe) {
      press.weights.emplace_back(node, 1.0 / static_cast<double>(probe.fine_probe.size()));
    }
  } else {
    press.weights = pressure_weights(model, probe.fine_inside);
  }
  if (!press.force_control) press.driven = probe.fine_probe;
  return press;
}

// Solves frame f at `ramp` (fraction of the peak force or depth) from x, leaves the solution in x,
// adds the Newton iterations and returns the probe's force (N) and torque (N m) on the block.
std::pair<Eigen::Vector3d, Eigen::Vector3d> solve_pressed_frame(const ProbePress& press, FemSolver& solver, int f,
                                                                double ramp, Eigen::VectorXd& x,
                                                                int& newton_iterations) {
  const StepeScenarioOptions& o = press.o;
  const Eigen::VectorXd& rest = press.model.rest_position_m();
  Eigen::VectorXd load;
  Eigen::VectorXd target(3 * ix(static_cast<int>(press.driven.size())));
  if (press.force_control) {
    load.setZero(3 * ix(press.model.node_count()));
    for (const auto& [node, w] : press.weights) {
      load.segment<3>(3 * ix(node)) = ramp * o.peak_force_n * w * press.probe.direction;
    }
  } else {
    for (std::size_t k = 0; k < press.driven.size(); ++k) {
      target.segment<3>(3 * ix(static_cast<int>(k))) =
          rest.segment<3>(3 * ix(press.driven[k])) + ramp * o.depth_m * press.probe.direction;
    }
  }
  const FemStaticResult result = solver.solve_static(target, load, FemStaticOptions{}, x);
  if (!result.converged) {
    throw std::runtime_error("make_stepe_scenario: the generation solve of frame " + std::to_string(f) +
                             " did not converge");
  }
  newton_iterations += result.iterations;
  x = result.position_m;
  const Eigen::VectorXd& on_block = press.force_control ? load : result.reaction_n;
  return {net_force(on_block, press.probe.fine_probe),
          net_torque(on_block, press.probe.fine_probe, rest, press.probe.centre)};
}

// One warm-started static solve per frame, in frame order.
GeneratedFrames generate_frames(const StepeScenarioOptions& o, const FemModel& model, const ProbeLayout& probe) {
  const ProbePress press = make_probe_press(o, model, probe);
  FemSolver solver(model, probe.fine_bottom, press.driven);
  GeneratedFrames g;
  Eigen::VectorXd x = model.rest_position_m();
  for (int f = 0; f < frame_count(o); ++f) {
    const double ramp = std::min(1.0, static_cast<double>(f) / o.ramp_frames);
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    Eigen::Vector3d torque = Eigen::Vector3d::Zero();
    if (f > 0) std::tie(force, torque) = solve_pressed_frame(press, solver, f, ramp, x, g.newton_iterations);
    g.positions.push_back(x);
    g.force_n.push_back(force);
    g.torque_nm.push_back(torque);
    double along = 0;
    for (int node : probe.fine_probe) {
      along += (x - model.rest_position_m()).segment<3>(3 * ix(node)).dot(probe.direction);
    }
    g.travel_m.push_back(along / static_cast<double>(probe.fine_probe.size()));
  }
  return g;
}

bool under_probe(const ProbeLayout& p, int node) { return std::binary_search(p.probe.begin(), p.probe.end(), node); }

// The recording's static fields: sizes, masses, fixed and driven nodes, files, contact, material.
void describe_recording(const StepeScenarioOptions& o, const FemModel& coarse_model, const ProbeLayout& p,
                        Recording& r) {
  const int n = coarse_model.node_count();
  r.name = o.name;
  r.dimension = 3;
  r.length_unit = "m";
  r.particle_count = n;
  r.masses.resize(uz(n));
  for (int i = 0; i < n; ++i) r.masses[uz(i)] = coarse_model.lumped_mass_kg()[i];
  r.fixed = p.coarse_bottom;
  if (o.declare_probe_driven) {
    for (int node : p.probe) {
      r.driven.push_back(
          DrivenWindow{node, -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()});
    }
  }
  r.files = {{"particles", "particles.csv"}, {"wrench", "wrench.csv"}, {"mesh", "mesh.vtk"}};
  r.wrench_applied_to = p.probe;
  r.material = {{"poisson_ratio", o.poisson_ratio}, {"density", o.density_kg_m3}};
}

// Top-face estimation nodes in the camera's view: the footprint only when observe_probe or driven.
std::vector<int> observed_nodes(const StepeScenarioOptions& o, const ProbeLayout& p) {
  std::vector<int> observed;
  for (int node : p.top_nodes) {
    if (!under_probe(p, node) || o.observe_probe || o.declare_probe_driven) observed.push_back(node);
  }
  return observed;
}

// Per frame: its time, the observed positions with camera noise (driven probe nodes exact) and the
// wrench with sensor noise. Draws from `normal` in frame order, positions before the wrench.
void record_frames(const StepeScenarioOptions& o, const GeneratedFrames& g, const std::vector<int>& to_fine,
                   const std::vector<int>& observed, const ProbeLayout& p, std::mt19937_64& rng,
                   std::normal_distribution<double>& normal, Recording& r) {
  const int frames = frame_count(o);
  const std::size_t frame_size = 3 * uz(r.particle_count);
  r.positions.assign(uz(frames) * frame_size, std::numeric_limits<double>::quiet_NaN());
  for (int f = 0; f < frames; ++f) {
    r.frame_times_s.push_back(f * o.frame_interval_s);
    for (int node : observed) {
      const bool exact = o.declare_probe_driven && under_probe(p, node);
      for (int a = 0; a < 3; ++a) {
        const double noise = exact ? 0.0 : o.position_noise_m * normal(rng);
        r.positions[uz(f) * frame_size + uz(3 * node + a)] = g.positions[uz(f)](3 * ix(to_fine[uz(node)]) + a) + noise;
      }
    }
    WrenchSample w;
    w.t_s = f * o.frame_interval_s;
    for (int a = 0; a < 3; ++a) {
      w.force_n[a] = g.force_n[uz(f)](a) + o.force_noise_n * normal(rng);
      w.torque_nm[a] = g.torque_nm[uz(f)](a) + 0.01 * o.force_noise_n * normal(rng);
    }
    r.wrench.push_back(w);
  }
}

// Gross tracking outliers: outlier_count distinct (frame >= 1, node) observations of the camera
// (never a driven probe node) moved by outlier_offset_m in a random direction. Returns their list.
nlohmann::json add_outliers(const StepeScenarioOptions& o, const std::vector<int>& observed, const ProbeLayout& p,
                            std::mt19937_64& rng, std::normal_distribution<double>& normal, Recording& r) {
  std::vector<int> camera;
  for (int node : observed) {
    if (!(o.declare_probe_driven && under_probe(p, node))) camera.push_back(node);
  }
  const int frames = frame_count(o);
  const std::size_t frame_size = 3 * uz(r.particle_count);
  nlohmann::json outliers = nlohmann::json::array();
  std::set<std::pair<int, int>> chosen;
  if (frames > 1 && !camera.empty()) {
    std::uniform_int_distribution<int> pick_frame(1, frames - 1);
    std::uniform_int_distribution<std::size_t> pick_node(0, camera.size() - 1);
    const std::size_t available = uz(frames - 1) * camera.size();
    while (chosen.size() < std::min(uz(o.outlier_count), available)) {
      const int f = pick_frame(rng);
      const int node = camera[pick_node(rng)];
      if (!chosen.insert({f, node}).second) continue;
      Eigen::Vector3d d(normal(rng), normal(rng), normal(rng));
      d = o.outlier_offset_m * d.normalized();
      for (int a = 0; a < 3; ++a) r.positions[uz(f) * frame_size + uz(3 * node + a)] += d(a);
      outliers.push_back({{"frame", f}, {"id", node}, {"offset_m", vector_json(d)}});
    }
  }
  return outliers;
}

const char* control_name(const StepeScenarioOptions& o) {
  return o.control == ProbeControl::force ? "force" : "displacement";
}

nlohmann::json recording_meta(const StepeScenarioOptions& o, const ProbeLayout& p) {
  return {
      {"scenario", "stepe_foam_indentation"},
      {"description",
       "simulated foam block on a table (bottom fixed), a probe pressing the top centre; a depth camera sees the "
       "top surface only (probe footprint hidden), a force sensor measures the probe force"},
      {"control", control_name(o)},
      {"probe_direction", vector_json(p.direction)},
      {"probe_footprint_m", {2 * p.half_x, 2 * p.half_y}},
      {"wrench", "force of the probe on the block; torque about the footprint centre (lever arms at rest)"},
      {"unobserved", "interior, side and bottom nodes, and the footprint under the probe: nan"},
      {"gravity", "not modelled"},
      {"frames", {{"rest", 1}, {"ramp", o.ramp_frames}, {"hold", o.hold_frames}}},
  };
}

// What the estimators must not see: E, both meshes, the noise-free per-frame wrench and travel,
// the noise levels and the outliers injected.
nlohmann::json truth_json(const StepeScenarioOptions& o, const ScenarioMeshes& meshes, int generation_nodes,
                          const GeneratedFrames& g, const std::vector<double>& frame_times_s,
                          const nlohmann::json& outliers) {
  const bool force_control = o.control == ProbeControl::force;
  nlohmann::json per_frame = nlohmann::json::array();
  for (int f = 0; f < frame_count(o); ++f) {
    per_frame.push_back({{"frame", f},
                         {"time_s", frame_times_s[uz(f)]},
                         {"force_n", vector_json(g.force_n[uz(f)])},
                         {"torque_nm", vector_json(g.torque_nm[uz(f)])},
                         {"probe_travel_m", g.travel_m[uz(f)]}});
  }
  return {
      {"scenario", "stepe_foam_indentation"},
      {"youngs_modulus", o.youngs_modulus_pa},
      {"poisson_ratio", o.poisson_ratio},
      {"block_size_m", vector_json(o.block_size_m)},
      {"estimation_mesh",
       {{"cells", o.cells},
        {"nodes", meshes.coarse.point_count()},
        {"tetrahedra", meshes.coarse.tet_count()},
        {"split", "mirrored_kuhn"}}},
      {"generation_mesh",
       {{"cells", meshes.fine_cells},
        {"nodes", generation_nodes},
        {"tetrahedra", meshes.fine.tet_count()},
        {"split", o.generation_split == BoxSplit::kuhn ? "kuhn" : "mirrored_kuhn"},
        {"inverse_crime",
         o.generation_refinement == std::array<int, 3>{1, 1, 1} && o.generation_split == BoxSplit::mirrored_kuhn}}},
      {"control", control_name(o)},
      {"probe_load", !force_control         ? "rigid bonded punch"
                     : o.equal_nodal_shares ? "equal shares on the footprint nodes"
                                            : "uniform pressure over the footprint"},
      {"peak_force_n", force_control ? o.peak_force_n : std::numeric_limits<double>::quiet_NaN()},
      {"depth_m", force_control ? std::numeric_limits<double>::quiet_NaN() : o.depth_m},
      {"tilt_deg", o.tilt_deg},
      {"position_noise_m", o.position_noise_m},
      {"force_noise_n", o.force_noise_n},
      {"outliers", outliers},
      {"seed", o.seed},
      {"frames", per_frame},
  };
}

}  // namespace

StepeScenario make_stepe_scenario(const StepeScenarioOptions& o) {
  check(o);
  const auto wall0 = std::chrono::steady_clock::now();
  const ScenarioMeshes meshes = make_meshes(o);
  const FemMaterial material = scenario_material(o);
  const FemModel model(meshes.fine, material);
  const FemModel coarse_model(meshes.coarse, material);
  const ProbeLayout probe = layout_probe(o, meshes);
  const GeneratedFrames generated = generate_frames(o, model, probe);

  // The recording on the estimation mesh. Every random draw comes from one generator, in a fixed
  // order (positions and wrench frame by frame, then the outliers): deterministic per seed.
  StepeScenario s;
  s.true_force_n = generated.force_n;
  s.generation_newton_iterations = generated.newton_iterations;
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Recording& r = s.recording;
  describe_recording(o, coarse_model, probe, r);
  const std::vector<int> observed = observed_nodes(o, probe);
  record_frames(o, generated, meshes.to_fine, observed, probe, rng, normal, r);
  const nlohmann::json outliers = add_outliers(o, observed, probe, rng, normal, r);
  r.meta = recording_meta(o, probe);
  r.mesh = meshes.coarse;
  finalize_recording(r);

  s.generation_nodes = model.node_count();
  s.truth = truth_json(o, meshes, s.generation_nodes, generated, r.frame_times_s, outliers);
  s.generation_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return s;
}

void write_stepe_scenario(const StepeScenario& scenario, const std::string& directory) {
  write_recording(scenario.recording, directory);
  const std::filesystem::path path = std::filesystem::path(directory) / "truth.json";
  std::ofstream out(path);
  out << scenario.truth.dump(2) << "\n";
  if (!out) throw std::runtime_error("write_stepe_scenario: cannot write " + path.string());
}

}  // namespace pliant::host::fem
