// The averaged-nodal-pressure formulation (FemVolumetric::nodal_average, fem_model.hpp): its
// forces are the gradient of its energy, its tangent the derivative of its forces, rigid motions
// cost nothing, a homogeneous strain is reproduced exactly (patch test), the solvers assemble the
// same tangent as stiffness_matrix(), and, the point of it, a coarse mesh of nearly incompressible
// material is no longer far too stiff: a bonded cylinder against CalculiX's converged quadratic
// elements (tests/host/data/calculix_locking_references.json, made by
// tools/reference/calculix_locking_references.py), and free vibration conserves energy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "pliant/host/fem/cylinder_mesh.hpp"
#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/fem/fem_modal.hpp"
#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_solver.hpp"

#ifndef PLIANT_TEST_DATA_DIR
#error "PLIANT_TEST_DATA_DIR must name tests/host/data"
#endif

namespace pliant::host::test {
namespace {

using fem::FemMaterial;
using fem::FemModel;
using fem::FemSolver;
using fem::FemVolumetric;

constexpr double kPi = 3.14159265358979323846;

FemMaterial material(double nu, FemVolumetric volumetric, double youngs = 1e5) {
  FemMaterial m;
  m.youngs_modulus_pa = youngs;
  m.poisson_ratio = nu;
  m.density_kg_m3 = 1100;
  m.volumetric = volumetric;
  return m;
}

// A small irregular box: a 3 x 3 x 2 cell box with every interior node jittered.
TetMesh jittered_box(unsigned seed) {
  TetMesh mesh = fem::make_box_tet_mesh(Eigen::Vector3d(0.03, 0.03, 0.02), {3, 3, 2});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < mesh.point_count(); ++i) {
    const double* p = &mesh.points[static_cast<std::size_t>(3 * i)];
    const bool interior =
        p[0] > 1e-9 && p[0] < 0.03 - 1e-9 && p[1] > 1e-9 && p[1] < 0.03 - 1e-9 && p[2] > 1e-9 && p[2] < 0.02 - 1e-9;
    if (!interior) continue;
    for (int d = 0; d < 3; ++d) mesh.points[static_cast<std::size_t>(3 * i + d)] += 0.0015 * u(rng);
  }
  return mesh;
}

// The nodes on the box's bottom face (z = 0): the supports of the dynamic checks.
std::vector<int> bottom_nodes(const FemModel& model) {
  std::vector<int> nodes;
  for (int i = 0; i < model.node_count(); ++i) {
    if (model.rest_position_m()[3 * i + 2] < 1e-9) nodes.push_back(i);
  }
  return nodes;
}

// Rest shape rotated by 0.7 rad about a tilted axis and moved, plus a random deformation.
Eigen::VectorXd deformed(const FemModel& model, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Matrix3d q = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::VectorXd x = model.rest_position_m();
  for (int i = 0; i < model.node_count(); ++i) {
    Eigen::Vector3d p = x.segment<3>(3 * i);
    p += amplitude * Eigen::Vector3d(u(rng), u(rng), u(rng));
    x.segment<3>(3 * i) = q * p + Eigen::Vector3d(0.1, -0.2, 0.05);
  }
  return x;
}

TEST(FemVolumetric, AutomaticChoosesNodalAveragingFromThePoissonRatio) {
  const TetMesh mesh = jittered_box(1);
  EXPECT_FALSE(FemModel(mesh, material(0.3, FemVolumetric::automatic)).nodal_volumetric());
  EXPECT_TRUE(FemModel(mesh, material(fem::kNodalAverageFromPoisson, FemVolumetric::automatic)).nodal_volumetric());
  EXPECT_TRUE(FemModel(mesh, material(0.3, FemVolumetric::nodal_average)).nodal_volumetric());
  EXPECT_FALSE(FemModel(mesh, material(0.49, FemVolumetric::element)).nodal_volumetric());
  FemModel model(mesh, material(0.45, FemVolumetric::automatic));
  EXPECT_EQ(model.material().volumetric, FemVolumetric::nodal_average);
  model.set_poisson_ratio(0.2);  // the choice is fixed at construction
  EXPECT_TRUE(model.nodal_volumetric());
}

TEST(FemVolumetric, NodalVolumesAndBulkModuliFollowTheElements) {
  const TetMesh mesh = jittered_box(2);
  FemModel model(mesh, material(0.45, FemVolumetric::nodal_average));
  EXPECT_NEAR(model.node_volume_m3().sum(), model.element_volume_m3().sum(), 1e-15);
  const double kappa = 1e5 * (model.unit_lambda() + 2.0 * model.unit_mu() / 3.0);
  EXPECT_NEAR(kappa, 1e5 / (3.0 * (1.0 - 2.0 * 0.45)), 1e-6);
  for (int a = 0; a < model.node_count(); ++a) EXPECT_NEAR(model.node_bulk_modulus_pa()[a], kappa, 1e-6 * kappa);
  // A stiffer element raises only its corners' bulk moduli, by its share of their volume.
  Eigen::VectorXd youngs = model.youngs_modulus_pa();
  youngs[0] = 3e5;
  model.set_youngs_modulus(youngs);
  for (int a = 0; a < model.node_count(); ++a) {
    bool corner = false;
    for (int node : model.elements()[0]) corner = corner || node == a;
    const double expected =
        corner ? kappa * (1.0 + 2.0 * 0.25 * model.element_volume_m3()[0] / model.node_volume_m3()[a]) : kappa;
    EXPECT_NEAR(model.node_bulk_modulus_pa()[a], expected, 1e-6 * kappa) << "node " << a;
  }
}

TEST(FemVolumetric, ForcesAreTheNegativeGradientOfTheEnergy) {
  const TetMesh mesh = jittered_box(3);
  const FemModel model(mesh, material(0.49, FemVolumetric::nodal_average));
  const Eigen::VectorXd x = deformed(model, 0.002, 4);
  Eigen::VectorXd force;
  fem::internal_force(model, x, force);
  const double h = 1e-7;
  double worst = 0;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    Eigen::VectorXd plus = x;
    Eigen::VectorXd minus = x;
    plus[i] += h;
    minus[i] -= h;
    const double gradient = (fem::elastic_energy(model, plus) - fem::elastic_energy(model, minus)) / (2 * h);
    worst = std::max(worst, std::abs(gradient + force[i]));
  }
  EXPECT_LT(worst, 1e-6 * force.cwiseAbs().maxCoeff());
}

TEST(FemVolumetric, RigidMotionCostsNoEnergyAndNoForce) {
  const TetMesh mesh = jittered_box(5);
  const FemModel model(mesh, material(0.495, FemVolumetric::nodal_average));
  const Eigen::VectorXd x = deformed(model, 0.0, 6);  // rotated and moved, not deformed
  Eigen::VectorXd force;
  fem::internal_force(model, x, force);
  EXPECT_LT(force.cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(std::abs(fem::elastic_energy(model, x)), 1e-12);
}

TEST(FemVolumetric, TangentAtRestIsTheDerivativeOfTheForces) {
  const TetMesh mesh = jittered_box(7);
  const FemModel model(mesh, material(0.49, FemVolumetric::nodal_average));
  const Eigen::MatrixXd k = Eigen::MatrixXd(fem::stiffness_matrix(model, model.rest_position_m()));
  EXPECT_LT((k - k.transpose()).cwiseAbs().maxCoeff(), 1e-9 * k.cwiseAbs().maxCoeff());
  std::mt19937 rng(8);
  std::normal_distribution<double> n(0.0, 1e-7);
  Eigen::VectorXd dx(model.dof_count());
  for (Eigen::Index i = 0; i < dx.size(); ++i) dx[i] = n(rng);
  Eigen::VectorXd plus;
  Eigen::VectorXd minus;
  fem::internal_force(model, model.rest_position_m() + dx, plus);
  fem::internal_force(model, model.rest_position_m() - dx, minus);
  const Eigen::VectorXd directional = -(plus - minus) / 2.0;
  EXPECT_LT((k * dx - directional).norm(), 1e-6 * directional.norm());
  // Positive semi-definite with exactly the six rigid modes in its null space.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(k);
  EXPECT_GT(eig.eigenvalues()[0], -1e-8 * eig.eigenvalues().maxCoeff());
  EXPECT_LT(eig.eigenvalues()[5], 1e-8 * eig.eigenvalues().maxCoeff());
  EXPECT_GT(eig.eigenvalues()[6], 1e-6 * eig.eigenvalues().maxCoeff());
}

TEST(FemVolumetric, HomogeneousStrainPassesThePatchTest) {
  // Boundary nodes driven by an affine map, interior nodes free: the exact solution is the affine
  // map everywhere, and the reactions on a face are the stress times its area.
  const TetMesh mesh = jittered_box(9);
  const FemModel model(mesh, material(0.49, FemVolumetric::nodal_average));
  Eigen::Matrix3d grad;
  grad << 1.004, 0.001, 0.0, 0.0, 0.997, 0.002, 0.001, 0.0, 1.003;
  std::vector<int> driven;
  Eigen::VectorXd target(0);
  for (int i = 0; i < model.node_count(); ++i) {
    const Eigen::Vector3d p = model.rest_position_m().segment<3>(3 * i);
    const bool boundary = p.x() < 1e-9 || p.x() > 0.03 - 1e-9 || p.y() < 1e-9 || p.y() > 0.03 - 1e-9 || p.z() < 1e-9 ||
                          p.z() > 0.02 - 1e-9;
    if (!boundary) continue;
    driven.push_back(i);
    target.conservativeResize(target.size() + 3);
    target.tail<3>() = grad * p;
  }
  FemSolver solver(model, {}, driven);
  const fem::FemStaticResult result = solver.solve_static(target, Eigen::VectorXd());
  ASSERT_TRUE(result.converged);
  for (int i = 0; i < model.node_count(); ++i) {
    const Eigen::Vector3d expected = grad * model.rest_position_m().segment<3>(3 * i);
    EXPECT_LT((result.position_m.segment<3>(3 * i) - expected).norm(), 1e-10) << "node " << i;
  }
}

TEST(FemVolumetric, SolverStepMatchesTheAssembledTangent) {
  // One backward-Euler step from rest with a small load: M (x - x0) / h^2 + K (x - x0) = f is
  // linear at rest, so the solver's one Newton iteration must equal the dense solve with
  // stiffness_matrix() (which is assembled separately, by triplets).
  const TetMesh mesh = jittered_box(10);
  const FemModel model(mesh, material(0.49, FemVolumetric::nodal_average));
  const std::vector<int> fixed = bottom_nodes(model);
  FemSolver solver(model, fixed, {});
  Eigen::VectorXd load = Eigen::VectorXd::Zero(model.dof_count());
  for (int i = 0; i < model.node_count(); ++i) load.segment<3>(3 * i) = Eigen::Vector3d(0.01, -0.02, -0.03);
  fem::FemState state = solver.rest_state();
  const double h = 0.01;
  solver.step(state, h, Eigen::VectorXd(), load);
  const Eigen::MatrixXd k = Eigen::MatrixXd(fem::stiffness_matrix(model, model.rest_position_m()));
  std::vector<int> free;
  std::vector<char> is_fixed(static_cast<std::size_t>(model.node_count()), 0);
  for (int node : fixed) is_fixed[static_cast<std::size_t>(node)] = 1;
  for (int i = 0; i < model.node_count(); ++i) {
    if (is_fixed[static_cast<std::size_t>(i)] == 0) free.push_back(i);
  }
  const Eigen::Index nf = 3 * static_cast<Eigen::Index>(free.size());
  Eigen::MatrixXd a(nf, nf);
  Eigen::VectorXd b(nf);
  for (std::size_t r = 0; r < free.size(); ++r) {
    for (std::size_t c = 0; c < free.size(); ++c) {
      a.block<3, 3>(3 * static_cast<Eigen::Index>(r), 3 * static_cast<Eigen::Index>(c)) =
          h * h * k.block<3, 3>(3 * free[r], 3 * free[c]);
    }
    a.block<3, 3>(3 * static_cast<Eigen::Index>(r), 3 * static_cast<Eigen::Index>(r)).diagonal().array() +=
        model.lumped_mass_kg()[free[r]];
    b.segment<3>(3 * static_cast<Eigen::Index>(r)) = h * h * load.segment<3>(3 * free[r]);
  }
  const Eigen::VectorXd dx = a.ldlt().solve(b);
  for (std::size_t r = 0; r < free.size(); ++r) {
    const Eigen::Vector3d moved =
        state.position_m.segment<3>(3 * free[r]) - model.rest_position_m().segment<3>(3 * free[r]);
    EXPECT_LT((moved - dx.segment<3>(3 * static_cast<Eigen::Index>(r))).norm(), 1e-9 * dx.norm());
  }
}

TEST(FemVolumetric, ModalFrequenciesMatchADenseEigensolve) {
  const TetMesh mesh = jittered_box(11);
  const FemModel model(mesh, material(0.49, FemVolumetric::nodal_average));
  const std::vector<int> fixed = bottom_nodes(model);
  fem::FemModalOptions options;
  options.mode_count = 4;
  const fem::FemModes modes = fem::modal_analysis(model, fixed, options);
  const Eigen::MatrixXd k = Eigen::MatrixXd(fem::stiffness_matrix(model, model.rest_position_m()));
  std::vector<Eigen::Index> dofs;
  std::vector<char> is_fixed(static_cast<std::size_t>(model.node_count()), 0);
  for (int node : fixed) is_fixed[static_cast<std::size_t>(node)] = 1;
  for (int i = 0; i < model.node_count(); ++i) {
    if (is_fixed[static_cast<std::size_t>(i)] == 0) dofs.insert(dofs.end(), {3 * i, 3 * i + 1, 3 * i + 2});
  }
  const Eigen::Index nd = static_cast<Eigen::Index>(dofs.size());
  Eigen::MatrixXd a(nd, nd);
  for (Eigen::Index r = 0; r < nd; ++r) {
    const Eigen::Index dr = dofs[static_cast<std::size_t>(r)];
    for (Eigen::Index c = 0; c < nd; ++c) {
      const Eigen::Index dc = dofs[static_cast<std::size_t>(c)];
      a(r, c) = k(dr, dc) / std::sqrt(model.lumped_mass_kg()[dr / 3] * model.lumped_mass_kg()[dc / 3]);
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a);
  for (int mode = 0; mode < 4; ++mode) {
    EXPECT_NEAR(modes.omega_rad_s[mode], std::sqrt(eig.eigenvalues()[mode]), 1e-6 * std::sqrt(eig.eigenvalues()[mode]))
        << "mode " << mode;
  }
}

TEST(FemVolumetric, UndampedNewmarkVibrationKeepsItsEnergy) {
  const TetMesh mesh = jittered_box(12);
  const FemModel model(mesh, material(0.495, FemVolumetric::nodal_average));
  const std::vector<int> fixed = bottom_nodes(model);
  FemSolver solver(model, fixed, {});
  fem::FemState state = solver.rest_state();
  for (int i = 0; i < model.node_count(); ++i) {
    if (!solver.is_constrained(i)) state.velocity_m_s.segment<3>(3 * i) = Eigen::Vector3d(0.02, 0.0, 0.01);
  }
  fem::FemStepOptions options;
  options.integrator = fem::FemIntegrator::newmark;
  options.newton_iterations = 4;
  options.newton_tolerance_m = 1e-13;
  const double start = fem::kinetic_energy(model, state.velocity_m_s);
  double lowest = start;
  double highest = start;
  for (int step = 0; step < 200; ++step) {
    solver.step(state, 2e-4, Eigen::VectorXd(), Eigen::VectorXd(), options);
    const double energy = fem::kinetic_energy(model, state.velocity_m_s) + fem::elastic_energy(model, state.position_m);
    lowest = std::min(lowest, energy);
    highest = std::max(highest, energy);
  }
  EXPECT_LT((highest - lowest) / start, 0.01);
}

// Apparent modulus factor F H / (E A delta) of a bonded cylinder pressed 1 % (static, small
// strain), A the cross-section of the mesh itself (the c-gon the structured mesh inscribes).
double bonded_cylinder_factor(const CylinderMeshDivisions& divisions, double nu, FemVolumetric volumetric) {
  const double diameter = 0.05;
  const double height = 0.03;
  const double delta = 0.0003;
  const TetMesh mesh = cylinder_tet_mesh(diameter, height, divisions);
  const FemModel model(mesh, material(nu, volumetric));
  const int section = mesh.point_count() / (divisions.axial + 1);
  std::vector<int> bottom;
  std::vector<int> top;
  for (int i = 0; i < section; ++i) bottom.push_back(i);
  for (int i = mesh.point_count() - section; i < mesh.point_count(); ++i) top.push_back(i);
  FemSolver solver(model, bottom, top);
  Eigen::VectorXd target(3 * static_cast<Eigen::Index>(top.size()));
  for (std::size_t k = 0; k < top.size(); ++k) {
    target.segment<3>(3 * static_cast<Eigen::Index>(k)) = model.rest_position_m().segment<3>(3 * top[k]);
    target[3 * static_cast<Eigen::Index>(k) + 2] -= delta;
  }
  const fem::FemStaticResult result = solver.solve_static(target, Eigen::VectorXd());
  const double force = std::abs(fem::net_force(result.reaction_n, top).z());
  const int c = divisions.circumferential;
  const double area = 0.25 * diameter * diameter * 0.5 * c * std::sin(2.0 * kPi / c);
  return force * height / (1e5 * area * delta);
}

struct CylinderReference {
  double nu = 0;
  double factor = 0;
};

std::vector<CylinderReference> calculix_cylinder_references() {
  std::ifstream file(std::string(PLIANT_TEST_DATA_DIR) + "/calculix_locking_references.json");
  if (!file) return {};
  const nlohmann::json doc = nlohmann::json::parse(file);
  std::vector<CylinderReference> out;
  for (const auto& item : doc.at("cases")) {
    if (item.at("problem") != "bonded_cylinder") continue;
    out.push_back({item.at("poisson_ratio").get<double>(), item.at("apparent_modulus_factor").get<double>()});
  }
  return out;
}

// Measured on the 399-node mesh below (fem_locking_bench prints the table): the averaged nodal
// pressure reads the bonded cylinder 5.5 % (nu 0.45) to 10.7 % (nu 0.495) too stiff, the element
// formulation 12 % to 60 %. Issue 17's goal is 3 %; what remains is the coarse linear
// tetrahedron's stiffness in the nearly isochoric bulge at the bonded rims (CalculiX's own
// quadratic tetrahedra at 8 mm are 5 % stiff at nu 0.495), not the volumetric lock.
constexpr double kCylinderTolerance = 0.12;
constexpr double kShareOfElementError = 0.5;

TEST(FemVolumetric, CoarseBondedCylinderAgreesWithCalculixWhereTheElementFormulationLocks) {
  const std::vector<CylinderReference> references = calculix_cylinder_references();
  ASSERT_FALSE(references.empty()) << "tests/host/data/calculix_locking_references.json is missing";
  const CylinderMeshDivisions coarse{2, 16, 6};  // 399 nodes: a mesh a user would give
  for (const CylinderReference& ref : references) {
    if (ref.nu < 0.44) continue;
    const double nodal = bonded_cylinder_factor(coarse, ref.nu, FemVolumetric::nodal_average);
    const double element = bonded_cylinder_factor(coarse, ref.nu, FemVolumetric::element);
    const double nodal_error = nodal / ref.factor - 1.0;
    const double element_error = element / ref.factor - 1.0;
    std::printf("nu %.3f  CalculiX %.4f  nodal_average %.4f (%+.1f %%)  element %.4f (%+.1f %%)\n", ref.nu, ref.factor,
                nodal, 100 * nodal_error, element, 100 * element_error);
    EXPECT_LT(std::abs(nodal_error), kCylinderTolerance) << "nu " << ref.nu;
    EXPECT_LT(std::abs(nodal_error), kShareOfElementError * std::abs(element_error)) << "nu " << ref.nu;
  }
}

}  // namespace
}  // namespace pliant::host::test
