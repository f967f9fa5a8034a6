#include "pliant/host/fem/bar_vibration_scenario.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_solver.hpp"

namespace pliant::host::fem {
namespace {

std::size_t uz(int i) { return static_cast<std::size_t>(i); }

void check_options(const BarVibrationOptions& o) {
  const auto bad = [](const std::string& what) { throw std::invalid_argument("bar vibration scenario: " + what); };
  if (!(o.size_m.array() > 0).all() || !o.size_m.allFinite()) bad("sizes must be positive");
  if (o.cells[0] < 1 || o.cells[1] < 1 || o.cells[2] < 1) bad("cells must be >= 1");
  if (!(o.density_kg_m3 > 0) || !(o.poisson_ratio > -1 && o.poisson_ratio < 0.5)) bad("bad density or Poisson ratio");
  if (o.control_youngs_modulus_pa.empty()) bad("at least one control modulus is needed");
  for (double e : o.control_youngs_modulus_pa) {
    if (!(e > 0) || !std::isfinite(e)) bad("moduli must be positive and finite");
  }
  if (!(o.rayleigh_alpha >= 0) || !(o.rayleigh_beta >= 0)) bad("Rayleigh coefficients must be >= 0");
  if (!o.load_force_n.allFinite() || !o.load_torque_nm.allFinite() ||
      (o.load_force_n.isZero(0.0) && o.load_torque_nm.isZero(0.0))) {
    bad("the load must be finite and not zero");
  }
  if (!(o.max_initial_displacement_m > 0) || !std::isfinite(o.max_initial_displacement_m)) bad("bad displacement");
  if (!(o.frame_rate_hz > 0) || !std::isfinite(o.frame_rate_hz) || o.frame_count < 3) bad("bad frame rate or count");
  if (o.generator_substeps < 1) bad("generator_substeps must be >= 1");
  if (!(o.noise_m >= 0) || !std::isfinite(o.noise_m)) bad("noise must be >= 0");
}

double max_node_displacement(const FemModel& model, const Eigen::VectorXd& position_m) {
  double largest = 0;
  for (int i = 0; i < model.node_count(); ++i) {
    largest = std::max(largest, (position_m.segment<3>(3 * i) - model.rest_position_m().segment<3>(3 * i)).norm());
  }
  return largest;
}

/// Per-tetrahedron modulus of k equal slabs along x in [0, length].
Eigen::VectorXd slab_values(const TetMesh& mesh, double length, const std::vector<double>& slab_moduli_pa) {
  const std::vector<Eigen::Vector3d> centroids = element_centroids(mesh);
  const int k = static_cast<int>(slab_moduli_pa.size());
  Eigen::VectorXd values(static_cast<Eigen::Index>(centroids.size()));
  for (std::size_t e = 0; e < centroids.size(); ++e) {
    const int slab = std::clamp(static_cast<int>(std::floor(centroids[e].x() / length * k)), 0, k - 1);
    values[static_cast<Eigen::Index>(e)] = slab_moduli_pa[uz(slab)];
  }
  return values;
}

}  // namespace

std::vector<int> box_surface_nodes(const TetMesh& mesh) {
  if (mesh.point_count() < 1) return {};
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (int i = 0; i < mesh.point_count(); ++i) {
    for (int a = 0; a < 3; ++a) {
      lo(a) = std::min(lo(a), mesh.points[3 * uz(i) + uz(a)]);
      hi(a) = std::max(hi(a), mesh.points[3 * uz(i) + uz(a)]);
    }
  }
  const double tolerance = 1e-9 * (hi - lo).norm();
  std::vector<int> surface;
  for (int i = 0; i < mesh.point_count(); ++i) {
    bool on_face = false;
    for (int a = 0; a < 3; ++a) {
      const double x = mesh.points[3 * uz(i) + uz(a)];
      on_face = on_face || std::abs(x - lo(a)) <= tolerance || std::abs(x - hi(a)) <= tolerance;
    }
    if (on_face) surface.push_back(i);
  }
  return surface;
}

BarVibrationScenario make_bar_vibration_scenario(const BarVibrationOptions& options) {
  check_options(options);
  BarVibrationScenario scenario;
  TetMesh mesh = make_box_tet_mesh(options.size_m, options.cells, BoxSplit::mirrored_kuhn);
  const double length = options.size_m.x();
  const int k = static_cast<int>(options.control_youngs_modulus_pa.size());
  for (int i = 0; i < k; ++i) {
    scenario.control_points_m.emplace_back(length * (i + 0.5) / k, 0.5 * options.size_m.y(), 0.5 * options.size_m.z());
  }
  scenario.control_youngs_modulus_pa = options.control_youngs_modulus_pa;
  scenario.rayleigh_alpha = options.rayleigh_alpha;
  scenario.rayleigh_beta = options.rayleigh_beta;
  if (options.slabs) {
    scenario.element_youngs_modulus_pa = slab_values(mesh, length, options.control_youngs_modulus_pa);
  } else {
    const MaterialMap map(mesh, scenario.control_points_m, options.material_map);
    scenario.element_youngs_modulus_pa = map.element_values(options.control_youngs_modulus_pa);
  }

  FemMaterial material;
  material.youngs_modulus_pa = options.control_youngs_modulus_pa.front();
  material.poisson_ratio = options.poisson_ratio;
  material.density_kg_m3 = options.density_kg_m3;
  material.rayleigh_alpha = options.rayleigh_alpha;
  material.rayleigh_beta = options.rayleigh_beta;
  FemModel model(mesh, material);
  model.set_youngs_modulus(scenario.element_youngs_modulus_pa);

  const double cell_x = length / options.cells[0];
  scenario.clamped_nodes = points_on_plane(mesh, 0, 0.0, 1e-6 * cell_x);
  scenario.tip_nodes = points_on_plane(mesh, 0, length, 1e-6 * cell_x);
  FemSolver solver(model, scenario.clamped_nodes, {});

  // Load scale from the linear regime: a load 1e-6 of the target's gives a proportional response.
  Eigen::VectorXd unit_load = Eigen::VectorXd::Zero(model.dof_count());
  add_spread_wrench(options.load_force_n, options.load_torque_nm, scenario.tip_nodes, model.rest_position_m(),
                    unit_load);
  const double probe = 1e-6;
  const FemStaticResult small = solver.solve_static(Eigen::VectorXd(), probe * unit_load);
  double scale = probe * options.max_initial_displacement_m / max_node_displacement(model, small.position_m);
  FemStaticOptions static_options;
  static_options.displacement_tolerance_m = 1e-12;
  // The nonlinear (corotational) response is a little softer or stiffer than the linear one:
  // secant corrections of the scale until the largest displacement is on target (to 1e-4).
  FemStaticResult loaded;
  for (int correction = 0;; ++correction) {
    loaded = solver.solve_static(Eigen::VectorXd(), scale * unit_load, static_options,
                                 correction > 0 ? loaded.position_m : Eigen::VectorXd());
    if (!loaded.converged) throw std::runtime_error("bar vibration scenario: the loaded static solve did not converge");
    const double ratio = options.max_initial_displacement_m / max_node_displacement(model, loaded.position_m);
    if (std::abs(ratio - 1) <= 1e-4 || correction == 3) break;
    scale *= ratio;
  }
  scenario.load_force_n = scale * options.load_force_n;
  scenario.load_torque_nm = scale * options.load_torque_nm;

  Recording& r = scenario.recording;
  r.name = k == 1 ? "bar_vibration" : "bar_vibration_" + std::to_string(k) + "ctrl";
  r.dimension = 3;
  r.length_unit = "m";
  r.particle_count = model.node_count();
  r.masses.assign(model.lumped_mass_kg().data(), model.lumped_mass_kg().data() + model.node_count());
  r.fixed = scenario.clamped_nodes;
  r.files = {{"particles", "particles.csv"}, {"mesh", "mesh.vtk"}};
  r.material = {{"poisson_ratio", options.poisson_ratio}, {"density", options.density_kg_m3}};

  const std::vector<int> observed = box_surface_nodes(mesh);
  const std::size_t frame_size = 3 * uz(model.node_count());
  r.frame_times_s.resize(uz(options.frame_count));
  r.positions.assign(uz(options.frame_count) * frame_size, std::numeric_limits<double>::quiet_NaN());
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const auto record = [&](int frame, const Eigen::VectorXd& position_m) {
    r.frame_times_s[uz(frame)] = frame / options.frame_rate_hz;
    double* slot = r.positions.data() + uz(frame) * frame_size;
    for (int id : observed) {
      for (int a = 0; a < 3; ++a) {
        const double n = options.noise_m > 0 ? options.noise_m * noise(rng) : 0.0;
        slot[3 * uz(id) + uz(a)] = position_m[3 * id + a] + n;
      }
    }
  };

  FemState state = solver.rest_state();
  state.position_m = loaded.position_m;
  record(0, state.position_m);
  FemStepOptions step;
  step.integrator = FemIntegrator::newmark;
  step.substeps = options.generator_substeps;
  step.newton_iterations = 3;
  step.newton_tolerance_m = 1e-9;
  const Eigen::VectorXd none;
  for (int f = 1; f < options.frame_count; ++f) {
    solver.step(state, 1.0 / options.frame_rate_hz, none, none, step);
    record(f, state.position_m);
  }

  nlohmann::json truth = nlohmann::json::object();
  truth["control_points_m"] = nlohmann::json::array();
  for (const Eigen::Vector3d& p : scenario.control_points_m) truth["control_points_m"].push_back({p.x(), p.y(), p.z()});
  truth["youngs_modulus"] = options.control_youngs_modulus_pa;
  truth["rayleigh_alpha"] = options.rayleigh_alpha;
  truth["rayleigh_beta"] = options.rayleigh_beta;
  if (options.slabs) {
    truth["slabs"] = static_cast<int>(options.control_youngs_modulus_pa.size());
  } else {
    truth["kernel_width_m"] = MaterialMap(mesh, scenario.control_points_m, options.material_map).kernel_width_m();
  }
  nlohmann::json generator = nlohmann::json::object();
  generator["scenario"] = "cantilever bar released from a static end load (Wang et al. 2015, Table 1)";
  generator["integrator"] = "newmark";
  generator["substeps_per_frame"] = options.generator_substeps;
  generator["newton"] = "up to 3 iterations per substep, to 1e-9 m";
  generator["load_force_n"] = {scenario.load_force_n.x(), scenario.load_force_n.y(), scenario.load_force_n.z()};
  generator["load_torque_nm"] = {scenario.load_torque_nm.x(), scenario.load_torque_nm.y(), scenario.load_torque_nm.z()};
  generator["max_initial_displacement_m"] = options.max_initial_displacement_m;
  generator["noise_m"] = options.noise_m;
  generator["seed"] = options.seed;
  generator["observed"] = "surface nodes, every frame; interior nodes nan";
  generator["gravity"] = "off";
  r.meta["truth"] = std::move(truth);
  r.meta["generator"] = std::move(generator);
  r.mesh = std::move(mesh);
  finalize_recording(r);
  return scenario;
}

}  // namespace pliant::host::fem
