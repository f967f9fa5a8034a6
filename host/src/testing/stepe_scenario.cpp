// The simulated foam-block indentation of stepe_scenario.hpp.
#include "pliant/host/fem/stepe_scenario.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <utility>

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

}  // namespace

StepeScenario make_stepe_scenario(const StepeScenarioOptions& o) {
  check(o);
  const auto wall0 = std::chrono::steady_clock::now();
  const std::array<int, 3> fine_cells{o.cells[0] * o.generation_refinement[0], o.cells[1] * o.generation_refinement[1],
                                      o.cells[2] * o.generation_refinement[2]};
  const TetMesh coarse = make_box_tet_mesh(o.block_size_m, o.cells, BoxSplit::mirrored_kuhn);
  const TetMesh fine = make_box_tet_mesh(o.block_size_m, fine_cells, o.generation_split);
  const int n = coarse.point_count();

  // Estimation node -> generation node.
  std::vector<int> to_fine(uz(n));
  for (int k = 0; k <= o.cells[2]; ++k) {
    for (int j = 0; j <= o.cells[1]; ++j) {
      for (int i = 0; i <= o.cells[0]; ++i) {
        const int c = grid_id(o.cells, i, j, k);
        const int f = grid_id(fine_cells, i * o.generation_refinement[0], j * o.generation_refinement[1],
                              k * o.generation_refinement[2]);
        for (int a = 0; a < 3; ++a) {
          if (std::abs(coarse.points[uz(3 * c + a)] - fine.points[uz(3 * f + a)]) > 1e-12) {
            throw std::logic_error("make_stepe_scenario: estimation and generation grids disagree");
          }
        }
        to_fine[uz(c)] = f;
      }
    }
  }

  FemMaterial material;
  material.youngs_modulus_pa = o.youngs_modulus_pa;
  material.poisson_ratio = o.poisson_ratio;
  material.density_kg_m3 = o.density_kg_m3;
  const FemModel model(fine, material);
  const FemModel coarse_model(coarse, material);

  const double top = o.block_size_m.z();
  const double tolerance = 1e-9 * o.block_size_m.norm();
  const Eigen::Vector3d centre(0.5 * o.block_size_m.x(), 0.5 * o.block_size_m.y(), top);
  const double half_x = o.probe_cells * o.block_size_m.x() / o.cells[0];
  const double half_y = o.probe_cells * o.block_size_m.y() / o.cells[1];
  auto in_footprint = [&](const TetMesh& mesh, int i) {
    const double x = mesh.points[uz(3 * i)];
    const double y = mesh.points[uz(3 * i + 1)];
    return std::abs(x - centre.x()) <= half_x + tolerance && std::abs(y - centre.y()) <= half_y + tolerance;
  };
  std::vector<int> fine_probe;
  std::vector<char> fine_inside(uz(fine.point_count()), 0);
  for (int i : points_on_plane(fine, 2, top, tolerance)) {
    if (in_footprint(fine, i)) {
      fine_probe.push_back(i);
      fine_inside[uz(i)] = 1;
    }
  }
  std::vector<int> probe;  // estimation nodes of the footprint: wrench.applied_to
  std::vector<int> top_nodes;
  for (int i : points_on_plane(coarse, 2, top, tolerance)) {
    top_nodes.push_back(i);
    if (in_footprint(coarse, i)) probe.push_back(i);
  }
  const std::vector<int> bottom = points_on_plane(fine, 2, 0.0, tolerance);
  std::vector<int> coarse_bottom = points_on_plane(coarse, 2, 0.0, tolerance);
  std::sort(coarse_bottom.begin(), coarse_bottom.end());

  const double tilt = o.tilt_deg * kPi / 180.0;
  const Eigen::Vector3d direction(std::sin(tilt), 0.0, -std::cos(tilt));
  const bool force_control = o.control == ProbeControl::force;
  std::vector<std::pair<int, double>> weights;
  if (o.equal_nodal_shares) {
    for (int node : fine_probe) weights.emplace_back(node, 1.0 / static_cast<double>(fine_probe.size()));
  } else {
    weights = pressure_weights(model, fine_inside);
  }
  const std::vector<int> driven = force_control ? std::vector<int>{} : fine_probe;
  FemSolver solver(model, bottom, driven);

  const int frames = 1 + o.ramp_frames + o.hold_frames;
  const int fn = model.node_count();
  std::vector<Eigen::VectorXd> positions;
  StepeScenario s;
  std::vector<Eigen::Vector3d> true_torque;
  std::vector<double> travel;
  Eigen::VectorXd x = model.rest_position_m();
  for (int f = 0; f < frames; ++f) {
    const double ramp = std::min(1.0, static_cast<double>(f) / o.ramp_frames);
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
    Eigen::Vector3d torque = Eigen::Vector3d::Zero();
    if (f > 0) {
      Eigen::VectorXd load;
      Eigen::VectorXd target(3 * ix(static_cast<int>(driven.size())));
      if (force_control) {
        load.setZero(3 * ix(fn));
        for (const auto& [node, w] : weights) load.segment<3>(3 * ix(node)) = ramp * o.peak_force_n * w * direction;
      } else {
        for (std::size_t k = 0; k < driven.size(); ++k) {
          target.segment<3>(3 * ix(static_cast<int>(k))) =
              model.rest_position_m().segment<3>(3 * ix(driven[k])) + ramp * o.depth_m * direction;
        }
      }
      const FemStaticResult result = solver.solve_static(target, load, FemStaticOptions{}, x);
      if (!result.converged) {
        throw std::runtime_error("make_stepe_scenario: the generation solve of frame " + std::to_string(f) +
                                 " did not converge");
      }
      s.generation_newton_iterations += result.iterations;
      x = result.position_m;
      // Force and torque of the probe on the block, lever arms at rest about the footprint centre.
      const Eigen::VectorXd& on_block = force_control ? load : result.reaction_n;
      force = net_force(on_block, fine_probe);
      torque = net_torque(on_block, fine_probe, model.rest_position_m(), centre);
    }
    positions.push_back(x);
    s.true_force_n.push_back(force);
    true_torque.push_back(torque);
    // Probe travel: the footprint's mean displacement along the probe direction.
    double along = 0;
    for (int node : fine_probe) along += (x - model.rest_position_m()).segment<3>(3 * ix(node)).dot(direction);
    travel.push_back(along / static_cast<double>(fine_probe.size()));
  }

  // The recording on the estimation mesh.
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Recording& r = s.recording;
  r.name = o.name;
  r.dimension = 3;
  r.length_unit = "m";
  r.particle_count = n;
  r.masses.resize(uz(n));
  for (int i = 0; i < n; ++i) r.masses[uz(i)] = coarse_model.lumped_mass_kg()[i];
  r.fixed = coarse_bottom;
  if (o.declare_probe_driven) {
    for (int node : probe) {
      r.driven.push_back(
          DrivenWindow{node, -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()});
    }
  }
  r.files = {{"particles", "particles.csv"}, {"wrench", "wrench.csv"}, {"mesh", "mesh.vtk"}};
  r.wrench_applied_to = probe;
  r.material = {{"poisson_ratio", o.poisson_ratio}, {"density", o.density_kg_m3}};
  std::vector<int> observed;
  for (int node : top_nodes) {
    const bool under_probe = std::binary_search(probe.begin(), probe.end(), node);
    if (!under_probe || o.observe_probe || o.declare_probe_driven) observed.push_back(node);
  }
  const std::size_t frame_size = 3 * uz(n);
  r.positions.assign(uz(frames) * frame_size, std::numeric_limits<double>::quiet_NaN());
  for (int f = 0; f < frames; ++f) {
    r.frame_times_s.push_back(f * o.frame_interval_s);
    for (int node : observed) {
      const bool exact = o.declare_probe_driven && std::binary_search(probe.begin(), probe.end(), node);
      for (int a = 0; a < 3; ++a) {
        const double noise = exact ? 0.0 : o.position_noise_m * normal(rng);
        r.positions[uz(f) * frame_size + uz(3 * node + a)] = positions[uz(f)](3 * ix(to_fine[uz(node)]) + a) + noise;
      }
    }
    WrenchSample w;
    w.t_s = f * o.frame_interval_s;
    for (int a = 0; a < 3; ++a) {
      w.force_n[a] = s.true_force_n[uz(f)](a) + o.force_noise_n * normal(rng);
      w.torque_nm[a] = true_torque[uz(f)](a) + 0.01 * o.force_noise_n * normal(rng);
    }
    r.wrench.push_back(w);
  }

  // Gross tracking outliers among camera observations (never the driven probe) of frames >= 1.
  std::vector<int> camera;
  for (int node : observed) {
    if (!(o.declare_probe_driven && std::binary_search(probe.begin(), probe.end(), node))) camera.push_back(node);
  }
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

  r.meta = {
      {"scenario", "stepe_foam_indentation"},
      {"description",
       "simulated foam block on a table (bottom fixed), a probe pressing the top centre; a depth camera sees the "
       "top surface only (probe footprint hidden), a force sensor measures the probe force"},
      {"control", force_control ? "force" : "displacement"},
      {"probe_direction", vector_json(direction)},
      {"probe_footprint_m", {2 * half_x, 2 * half_y}},
      {"wrench", "force of the probe on the block; torque about the footprint centre (lever arms at rest)"},
      {"unobserved", "interior, side and bottom nodes, and the footprint under the probe: nan"},
      {"gravity", "not modelled"},
      {"frames", {{"rest", 1}, {"ramp", o.ramp_frames}, {"hold", o.hold_frames}}},
  };
  r.mesh = coarse;
  finalize_recording(r);

  nlohmann::json per_frame = nlohmann::json::array();
  for (int f = 0; f < frames; ++f) {
    per_frame.push_back({{"frame", f},
                         {"time_s", r.frame_times_s[uz(f)]},
                         {"force_n", vector_json(s.true_force_n[uz(f)])},
                         {"torque_nm", vector_json(true_torque[uz(f)])},
                         {"probe_travel_m", travel[uz(f)]}});
  }
  s.generation_nodes = fn;
  s.generation_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  s.truth = {
      {"scenario", "stepe_foam_indentation"},
      {"youngs_modulus", o.youngs_modulus_pa},
      {"poisson_ratio", o.poisson_ratio},
      {"block_size_m", vector_json(o.block_size_m)},
      {"estimation_mesh",
       {{"cells", o.cells}, {"nodes", n}, {"tetrahedra", coarse.tet_count()}, {"split", "mirrored_kuhn"}}},
      {"generation_mesh",
       {{"cells", fine_cells},
        {"nodes", fn},
        {"tetrahedra", fine.tet_count()},
        {"split", o.generation_split == BoxSplit::kuhn ? "kuhn" : "mirrored_kuhn"},
        {"inverse_crime",
         o.generation_refinement == std::array<int, 3>{1, 1, 1} && o.generation_split == BoxSplit::mirrored_kuhn}}},
      {"control", force_control ? "force" : "displacement"},
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
