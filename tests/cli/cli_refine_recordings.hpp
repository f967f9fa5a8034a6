// Recordings for the `pliant refine` tests, written with pliant::host: a coarse vibrating bar
// (the trajectory estimator) and a cantilever sagging under gravity (the rest shape).
#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pliant/host/fem/bar_vibration_scenario.hpp"
#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_solver.hpp"
#include "pliant/host/fem/mesh_io.hpp"
#include "pliant/host/fem/stepe_scenario.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::cli_test {

/// A coarse Table 1 bar (Wang et al.; bar_vibration_scenario.hpp): 0.8 x 0.05 x 0.05 m, 8 x 2 x 2
/// cells (192 tetrahedra, 81 nodes), surface nodes observed at 30 Hz for 4 s after release.
/// Truth: E per control point (one value: uniform), rayleigh_alpha 2e-2 1/s, rayleigh_beta 1e-3 s.
inline host::fem::BarVibrationScenario make_coarse_bar(std::vector<double> control_youngs_modulus_pa = {6.8e5}) {
  host::fem::BarVibrationOptions options;
  options.cells = {8, 2, 2};
  options.frame_count = 120;
  options.generator_substeps = 16;
  options.control_youngs_modulus_pa = std::move(control_youngs_modulus_pa);
  return host::fem::make_bar_vibration_scenario(options);
}

/// A coarse STEPE foam block (stepe_scenario.hpp, as the host estimator tests use it): 6 x 4 x 3
/// cells, a probe pushing 3 x 3 nodes of the top face with up to 300 N (force control, measured
/// with 0.2 N noise), the rest of the top face tracked with 0.1 mm noise. Generated on the same
/// mesh (the test is of the command, not of the discretisation). Truth: E = 454 kPa.
inline host::fem::StepeScenario make_coarse_stepe() {
  host::fem::StepeScenarioOptions options;
  options.cells = {6, 4, 3};
  options.generation_refinement = {1, 1, 1};
  options.probe_cells = 1;
  options.peak_force_n = 300;
  options.position_noise_m = 0.1e-3;
  return host::fem::make_stepe_scenario(options);
}

/// A cantilever sagging under its own weight, seen once at rest: the true rest shape and the
/// recording of what a camera sees (mesh.vtk = the observed, sagged shape; every node observed in
/// the single frame; the clamped x = 0 face fixed; youngs_modulus, density, poisson_ratio and
/// gravity given).
struct SagCase {
  Eigen::VectorXd true_rest_m;
  host::Recording recording;
};

constexpr double kSagLength = 0.2;  // m

inline SagCase make_sag_case() {
  const host::TetMesh rest =
      host::fem::make_box_tet_mesh(Eigen::Vector3d(kSagLength, 0.03, 0.03), {10, 2, 2},
                                   host::fem::BoxSplit::mirrored_kuhn, Eigen::Vector3d(0, -0.015, -0.015));
  host::fem::FemMaterial material;
  material.youngs_modulus_pa = 1e6;
  material.poisson_ratio = 0.3;
  material.density_kg_m3 = 1000;
  material.gravity_m_s2 = Eigen::Vector3d(0, 0, -9.81);
  const host::fem::FemModel model(rest, material);
  const std::vector<int> fixed = host::fem::points_on_plane(rest, 0, 0.0, 1e-9);
  host::fem::FemSolver solver(model, fixed, {});
  host::fem::FemStaticOptions options;
  options.displacement_tolerance_m = 1e-13;
  options.max_iterations = 500;
  const host::fem::FemStaticResult sagged = solver.solve_static(Eigen::VectorXd(), Eigen::VectorXd(), options);
  if (!sagged.converged) throw std::runtime_error("sag case: static solve did not converge");

  SagCase c;
  c.true_rest_m = Eigen::Map<const Eigen::VectorXd>(rest.points.data(), static_cast<Eigen::Index>(rest.points.size()));
  host::Recording& r = c.recording;
  r.name = "sagging_bar";
  r.dimension = 3;
  r.length_unit = "m";
  r.particle_count = rest.point_count();
  r.masses.assign(static_cast<std::size_t>(r.particle_count), 1.0);
  r.fixed = fixed;
  r.material = {{"youngs_modulus", 1e6}, {"density", 1000.0}, {"poisson_ratio", 0.3}};
  r.gravity = std::vector<double>{0.0, 0.0, -9.81};
  host::TetMesh seen = rest;
  seen.points.assign(sagged.position_m.data(), sagged.position_m.data() + sagged.position_m.size());
  r.mesh = seen;
  r.rest_positions = seen.points;
  r.frame_times_s = {0.0};
  r.positions = seen.points;
  return c;
}

/// Writes `mesh` as gmsh MSH 4.1.
inline void write_msh_file(const host::TetMesh& mesh, const std::filesystem::path& path) {
  std::ofstream out(path);
  host::write_msh(mesh, out);
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace pliant::cli_test
