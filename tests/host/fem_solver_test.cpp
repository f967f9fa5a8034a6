// FemSolver: input checks, the static solve against an independent sparse solver, patch tests
// (uniaxial stress driven on the boundary, bar tension under a traction), reactions balancing the
// loads, driven and fixed nodes, substeps, and parameters changed through the model.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

#include "fem_test_meshes.hpp"
#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_solver.hpp"

namespace pliant::host::test {
namespace {

using fem::FemMaterial;
using fem::FemModel;
using fem::FemSolver;

FemMaterial material(double youngs, double nu, double density = 1000) {
  FemMaterial m;
  m.youngs_modulus_pa = youngs;
  m.poisson_ratio = nu;
  m.density_kg_m3 = density;
  return m;
}

Eigen::VectorXd none() { return Eigen::VectorXd(); }

// Traction-consistent nodal forces: total force `force` spread over the plane x = value in
// proportion to each node's share of the face area.
Eigen::VectorXd traction(const FemModel& model, double x_value, const Eigen::Vector3d& force) {
  const std::vector<double> weight = face_area_weights(model, 0, x_value);
  double area = 0;
  for (double w : weight) area += w;
  Eigen::VectorXd f = Eigen::VectorXd::Zero(model.dof_count());
  for (int i = 0; i < model.node_count(); ++i) f.segment<3>(3 * i) = force * weight[static_cast<std::size_t>(i)] / area;
  return f;
}

TEST(FemSolver, RejectsBadInput) {
  const TetMesh mesh = ipc_mesh("bar-186.msh");
  const FemModel model(mesh, material(1e5, 0.3));
  EXPECT_THROW(FemSolver(model, {0, 0}, {}), std::invalid_argument);
  EXPECT_THROW(FemSolver(model, {0}, {0}), std::invalid_argument);
  EXPECT_THROW(FemSolver(model, {-1}, {}), std::invalid_argument);
  EXPECT_THROW(FemSolver(model, {}, {model.node_count()}), std::invalid_argument);
  const std::vector<int> clamp = fem::points_on_plane(mesh, 0, 0.0, 1e-9);
  FemSolver solver(model, clamp, {1});
  fem::FemState state = solver.rest_state();
  const Eigen::VectorXd driven = model.rest_position_m().segment<3>(3);
  EXPECT_THROW(solver.step(state, 0.0, driven, none()), std::invalid_argument);
  EXPECT_THROW(solver.step(state, -1e-3, driven, none()), std::invalid_argument);
  EXPECT_THROW(solver.step(state, 1e-3, Eigen::VectorXd::Zero(6), none()), std::invalid_argument);
  EXPECT_THROW(solver.step(state, 1e-3, driven, Eigen::VectorXd::Zero(5)), std::invalid_argument);
  Eigen::VectorXd bad_force = Eigen::VectorXd::Zero(model.dof_count());
  bad_force[7] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(solver.step(state, 1e-3, driven, bad_force), std::invalid_argument);
  fem::FemStepOptions options;
  options.substeps = 0;
  EXPECT_THROW(solver.step(state, 1e-3, driven, none(), options), std::invalid_argument);
  fem::FemState short_state = state;
  short_state.velocity_m_s.resize(3);
  EXPECT_THROW(solver.step(short_state, 1e-3, driven, none()), std::invalid_argument);
  EXPECT_NO_THROW(solver.step(state, 1e-3, driven, none()));
  // Nothing holds the body: the static stiffness is singular.
  FemSolver loose(model, {}, {});
  EXPECT_THROW(loose.solve_static(none(), traction(model, 10.0, {0, 0, 1})), std::runtime_error);
  EXPECT_THROW(fem::add_spread_force({1, 0, 0}, {}, model.node_count(), bad_force), std::invalid_argument);
  Eigen::VectorXd load;
  EXPECT_THROW(fem::add_spread_wrench({0, 0, 0}, {0, 0, 1}, {3}, model.rest_position_m(), load), std::invalid_argument);
}

TEST(FemSolver, LinearStaticMatchesSparseLdltOracle) {
  const TetMesh mesh = ipc_mesh("bar-651.msh");
  const FemModel model(mesh, material(1e6, 0.3));
  const std::vector<int> clamp = fem::points_on_plane(mesh, 0, 0.0, 1e-9);
  FemSolver solver(model, clamp, {});
  // Tiny load: the corotational response equals the linear one to ~1e-9.
  const Eigen::VectorXd load = traction(model, 10.0, {1e-4, -2e-4, 3e-4});
  const fem::FemStaticResult result = solver.solve_static(none(), load);
  ASSERT_TRUE(result.converged);
  // Oracle: Eigen's simplicial LDL^T on the free block of the assembled rest stiffness.
  const Eigen::SparseMatrix<double> k = fem::stiffness_matrix(model, model.rest_position_m());
  std::vector<int> map(static_cast<std::size_t>(model.dof_count()), 0);
  for (int node : clamp) {
    for (int d = 0; d < 3; ++d) map[static_cast<std::size_t>(3 * node + d)] = -1;
  }
  int free = 0;
  for (int& m : map) m = m < 0 ? -1 : free++;
  std::vector<Eigen::Triplet<double>> triplets;
  for (int col = 0; col < k.outerSize(); ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(k, col); it; ++it) {
      const int r = map[static_cast<std::size_t>(it.row())];
      const int c = map[static_cast<std::size_t>(col)];
      if (r >= 0 && c >= 0) triplets.emplace_back(r, c, it.value());
    }
  }
  Eigen::SparseMatrix<double> kff(free, free);
  kff.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::VectorXd rhs(free);
  for (int i = 0; i < model.dof_count(); ++i) {
    if (map[static_cast<std::size_t>(i)] >= 0) rhs[map[static_cast<std::size_t>(i)]] = load[i];
  }
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(kff);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  const Eigen::VectorXd u = ldlt.solve(rhs);
  Eigen::VectorXd ours(free);
  for (int i = 0; i < model.dof_count(); ++i) {
    if (map[static_cast<std::size_t>(i)] >= 0)
      ours[map[static_cast<std::size_t>(i)]] = result.position_m[i] - model.rest_position_m()[i];
  }
  EXPECT_LT((ours - u).norm(), 1e-6 * u.norm());
}

// Uniaxial stress patch test: every boundary node is driven with the exact field of a bar
// stretched by strain eps along x (lateral contraction -nu eps), rotated rigidly by Q and
// shifted by t. The interior must follow the same field, the end faces carry E eps A, and the
// lateral faces need no force at all (their contraction is free).
TEST(FemSolver, PatchTestUniaxialStress) {
  const double youngs = 2e5;
  const double nu = 0.3;
  const double eps = 0.02;
  const Eigen::Vector3d size(2.0, 1.5, 1.0);
  const TetMesh mesh = fem::make_box_tet_mesh(size, {4, 3, 3});
  const FemModel model(mesh, material(youngs, nu));
  for (const double angle : {0.0, 2.5}) {
    const Eigen::Matrix3d q = Eigen::AngleAxisd(angle, Eigen::Vector3d(1, 1, -2).normalized()).toRotationMatrix();
    const Eigen::Vector3d t(0.3, -0.2, 0.7);
    auto exact = [&](const Eigen::Vector3d& p) {
      return Eigen::Vector3d(q * Eigen::Vector3d(p.x() * (1 + eps), p.y() * (1 - nu * eps), p.z() * (1 - nu * eps)) +
                             t);
    };
    std::vector<int> boundary;
    for (int i = 0; i < model.node_count(); ++i) {
      const Eigen::Vector3d p = model.rest_position_m().segment<3>(3 * i);
      bool on = false;
      for (int d = 0; d < 3; ++d) on = on || std::abs(p[d]) < 1e-9 || std::abs(p[d] - size[d]) < 1e-9;
      if (on) boundary.push_back(i);
    }
    FemSolver solver(model, {}, boundary);
    Eigen::VectorXd driven(3 * static_cast<Eigen::Index>(boundary.size()));
    for (std::size_t k = 0; k < boundary.size(); ++k) {
      driven.segment<3>(3 * static_cast<Eigen::Index>(k)) = exact(model.rest_position_m().segment<3>(3 * boundary[k]));
    }
    const fem::FemStaticResult result = solver.solve_static(driven, none());
    ASSERT_TRUE(result.converged);
    for (int i = 0; i < model.node_count(); ++i) {
      EXPECT_LT((result.position_m.segment<3>(3 * i) - exact(model.rest_position_m().segment<3>(3 * i))).norm(), 1e-10)
          << "node " << i;
    }
    const std::vector<int> end = fem::points_on_plane(mesh, 0, size.x(), 1e-9);
    const std::vector<int> start = fem::points_on_plane(mesh, 0, 0.0, 1e-9);
    const double expected = youngs * eps * size.y() * size.z();
    EXPECT_LT((fem::net_force(result.reaction_n, end) - q * Eigen::Vector3d(expected, 0, 0)).norm(), 1e-9 * expected);
    EXPECT_LT((fem::net_force(result.reaction_n, start) + q * Eigen::Vector3d(expected, 0, 0)).norm(), 1e-9 * expected);
    for (int i : boundary) {
      const double x = model.rest_position_m()[3 * i];
      if (x > 1e-9 && x < size.x() - 1e-9) {
        EXPECT_LT(result.reaction_n.segment<3>(3 * i).norm(), 1e-9 * expected) << "lateral node " << i;
      }
    }
  }
}

// Bar in tension under a uniform end traction, nu = 0: u(x) = F x / (E A) exactly, at any load
// (the deformation gradient is symmetric, so the rotation is the identity).
TEST(FemSolver, BarTensionUnderTraction) {
  const TetMesh mesh = ipc_mesh("bar-651.msh");
  const double youngs = 1e5;
  const FemModel model(mesh, material(youngs, 0.0));
  const std::vector<int> clamp = fem::points_on_plane(mesh, 0, 0.0, 1e-9);
  FemSolver solver(model, clamp, {});
  const double force = 5000.0;  // 1 % strain
  const fem::FemStaticResult result = solver.solve_static(none(), traction(model, 10.0, {force, 0, 0}));
  ASSERT_TRUE(result.converged);
  const double area = 0.5;
  for (int i = 0; i < model.node_count(); ++i) {
    const Eigen::Vector3d p = model.rest_position_m().segment<3>(3 * i);
    const Eigen::Vector3d expected = p + Eigen::Vector3d(force * p.x() / (youngs * area), 0, 0);
    EXPECT_LT((result.position_m.segment<3>(3 * i) - expected).norm(), 1e-9) << "node " << i;
  }
  EXPECT_LT((fem::net_force(result.reaction_n, clamp) + Eigen::Vector3d(force, 0, 0)).norm(), 1e-8 * force);
}

TEST(FemSolver, ReactionsBalanceLoadsAndGravityStaticAndDynamic) {
  const TetMesh mesh = ipc_mesh("bar-651.msh");
  FemMaterial m = material(2e8, 0.3, 900);  // gravity sag ~7 % of the length
  m.gravity_m_s2 = Eigen::Vector3d(0, 0, -9.81);
  m.rayleigh_alpha = 0.5;
  m.rayleigh_beta = 0.01;
  const FemModel model(mesh, m);
  const std::vector<int> clamp = fem::points_on_plane(mesh, 0, 0.0, 1e-9);
  const std::vector<int> tip = fem::points_on_plane(mesh, 0, 10.0, 1e-9);
  FemSolver solver(model, clamp, {});
  Eigen::VectorXd load;
  fem::add_spread_wrench({300, -200, -1500}, {0, 0, 0}, tip, model.rest_position_m(), load);
  const Eigen::Vector3d weight = model.total_mass_kg() * m.gravity_m_s2;
  const Eigen::Vector3d applied = fem::net_force(load, tip);
  EXPECT_LT((applied - Eigen::Vector3d(300, -200, -1500)).norm(), 1e-12);
  const fem::FemStaticResult result = solver.solve_static(none(), load);
  ASSERT_TRUE(result.converged);
  const double scale = (applied + weight).norm();
  EXPECT_LT((fem::net_force(result.reaction_n, clamp) + applied + weight).norm(), 1e-8 * scale);
  // Moment balance about the origin, at the deformed positions.
  std::vector<int> all(static_cast<std::size_t>(model.node_count()));
  for (int i = 0; i < model.node_count(); ++i) all[static_cast<std::size_t>(i)] = i;
  Eigen::VectorXd external = load;
  for (int i = 0; i < model.node_count(); ++i) external.segment<3>(3 * i) += model.lumped_mass_kg()[i] * m.gravity_m_s2;
  const Eigen::Vector3d moment = fem::net_torque(result.reaction_n, clamp, result.position_m, Eigen::Vector3d::Zero()) +
                                 fem::net_torque(external, all, result.position_m, Eigen::Vector3d::Zero());
  EXPECT_LT(moment.norm(), 1e-8 * scale * 10.0);
  // Dynamics, Newton converged each step: reactions = total inertia + alpha damping - loads.
  fem::FemState state = solver.rest_state();
  fem::FemStepOptions options;
  options.newton_iterations = 20;
  options.newton_tolerance_m = 1e-13;
  for (const fem::FemIntegrator integrator : {fem::FemIntegrator::backward_euler, fem::FemIntegrator::newmark}) {
    options.integrator = integrator;
    for (int k = 0; k < 10; ++k) {
      solver.step(state, 0.01, none(), load, options);
      Eigen::Vector3d inertia = Eigen::Vector3d::Zero();
      for (int i = 0; i < model.node_count(); ++i) {
        inertia += model.lumped_mass_kg()[i] * (state.acceleration_m_s2.segment<3>(3 * i) +
                                                m.rayleigh_alpha * state.velocity_m_s.segment<3>(3 * i));
      }
      EXPECT_LT((fem::net_force(solver.reaction_n(), clamp) - (inertia - applied - weight)).norm(), 1e-7 * scale)
          << "step " << k;
    }
  }
}

TEST(FemSolver, DrivenNodesFollowFixedNodesStay) {
  const TetMesh mesh = fem::make_box_tet_mesh({0.1, 0.02, 0.02}, {10, 2, 2});
  FemMaterial m = material(5e5, 0.4, 1100);
  m.gravity_m_s2 = Eigen::Vector3d(0, 0, -9.81);
  const FemModel model(mesh, m);
  const std::vector<int> clamp = fem::points_on_plane(mesh, 0, 0.0, 1e-9);
  const std::vector<int> tool = fem::points_on_plane(mesh, 0, 0.1, 1e-9);
  FemSolver solver(model, clamp, tool);
  EXPECT_EQ(solver.free_node_count(), model.node_count() - static_cast<int>(clamp.size() + tool.size()));
  fem::FemState state = solver.rest_state();
  Eigen::VectorXd rest_tool(3 * static_cast<Eigen::Index>(tool.size()));
  for (std::size_t k = 0; k < tool.size(); ++k)
    rest_tool.segment<3>(3 * static_cast<Eigen::Index>(k)) = model.rest_position_m().segment<3>(3 * tool[k]);
  const double dt = 1e-3;
  for (int k = 1; k <= 50; ++k) {
    Eigen::VectorXd target = rest_tool;
    for (std::size_t j = 0; j < tool.size(); ++j)
      target[3 * static_cast<Eigen::Index>(j) + 2] += 0.005 * std::sin(0.1 * k);
    fem::FemStepOptions options;
    options.integrator = k % 2 == 0 ? fem::FemIntegrator::newmark : fem::FemIntegrator::backward_euler;
    options.substeps = 1 + k % 3;
    solver.step(state, dt, target, none(), options);
    for (std::size_t j = 0; j < tool.size(); ++j) {
      EXPECT_EQ((state.position_m.segment<3>(3 * tool[j]) - target.segment<3>(3 * static_cast<Eigen::Index>(j))).norm(),
                0.0);
    }
    for (int node : clamp) {
      EXPECT_EQ((state.position_m.segment<3>(3 * node) - model.rest_position_m().segment<3>(3 * node)).norm(), 0.0);
      EXPECT_EQ(state.velocity_m_s.segment<3>(3 * node).norm(), 0.0);
    }
    for (int i = 0; i < model.node_count(); ++i) {
      if (!solver.is_constrained(i)) {
        EXPECT_EQ(solver.reaction_n().segment<3>(3 * i).norm(), 0.0);
      }
    }
  }
  EXPECT_NEAR(state.time_s, 50 * dt, 1e-12);
}

// A tool that starts from rest and then moves at constant speed: with the secant rule (default)
// the driven nodes' velocity is that speed from the first step on; the trapezoidal rule, started
// from rest, alternates between 0 and twice the speed for ever.
TEST(FemSolver, DrivenVelocityUnderNewmark) {
  const TetMesh mesh = fem::make_box_tet_mesh({0.1, 0.02, 0.02}, {6, 2, 2});
  const FemModel model(mesh, material(5e5, 0.3, 1000));
  const std::vector<int> clamp = fem::points_on_plane(mesh, 0, 0.0, 1e-9);
  const std::vector<int> tool = fem::points_on_plane(mesh, 0, 0.1, 1e-9);
  FemSolver solver(model, clamp, tool);
  const double speed = 0.01;
  const double dt = 1e-3;
  for (const fem::FemDrivenVelocity rule : {fem::FemDrivenVelocity::secant, fem::FemDrivenVelocity::trapezoidal}) {
    fem::FemStepOptions options;
    options.integrator = fem::FemIntegrator::newmark;
    options.driven_velocity = rule;
    fem::FemState state = solver.rest_state();
    Eigen::VectorXd target(3 * static_cast<Eigen::Index>(tool.size()));
    for (std::size_t j = 0; j < tool.size(); ++j)
      target.segment<3>(3 * static_cast<Eigen::Index>(j)) = model.rest_position_m().segment<3>(3 * tool[j]);
    for (int k = 1; k <= 6; ++k) {
      for (std::size_t j = 0; j < tool.size(); ++j) target[3 * static_cast<Eigen::Index>(j) + 2] += speed * dt;
      solver.step(state, dt, target, none(), options);
      const double vz = state.velocity_m_s[3 * tool[0] + 2];
      if (rule == fem::FemDrivenVelocity::secant) {
        EXPECT_NEAR(vz, speed, 1e-12) << "step " << k;
      } else {
        EXPECT_NEAR(vz, k % 2 == 1 ? 2 * speed : 0.0, 1e-12) << "step " << k;
      }
    }
  }
}

TEST(FemSolver, SubstepsEqualSmallerSteps) {
  const TetMesh mesh = fem::make_box_tet_mesh({0.1, 0.02, 0.02}, {8, 2, 2});
  FemMaterial m = material(5e5, 0.3, 1000);
  m.gravity_m_s2 = Eigen::Vector3d(0, -9.81, 0);
  m.rayleigh_beta = 1e-3;
  const FemModel model(mesh, m);
  const std::vector<int> clamp = fem::points_on_plane(mesh, 0, 0.0, 1e-9);
  FemSolver solver(model, clamp, {});
  for (const fem::FemIntegrator integrator : {fem::FemIntegrator::backward_euler, fem::FemIntegrator::newmark}) {
    fem::FemStepOptions coarse;
    coarse.integrator = integrator;
    coarse.substeps = 4;
    fem::FemStepOptions fine;
    fine.integrator = integrator;
    fem::FemState a = solver.rest_state();
    fem::FemState b = solver.rest_state();
    for (int k = 0; k < 5; ++k) {
      solver.step(a, 4e-3, none(), none(), coarse);
      for (int s = 0; s < 4; ++s) solver.step(b, 1e-3, none(), none(), fine);
    }
    EXPECT_LT((a.position_m - b.position_m).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_LT((a.velocity_m_s - b.velocity_m_s).cwiseAbs().maxCoeff(), 1e-11);
  }
}

// The estimator workflow: change the model's Young's moduli (per element) and solve again with the
// same solver; a uniformly doubled E halves a linear deflection.
TEST(FemSolver, PicksUpModelParameterChanges) {
  const TetMesh mesh = ipc_mesh("bar-651.msh");
  FemModel model(mesh, material(1e6, 0.3));
  const std::vector<int> clamp = fem::points_on_plane(mesh, 0, 0.0, 1e-9);
  FemSolver solver(model, clamp, {});
  const Eigen::VectorXd load = traction(model, 10.0, {0, 0, -1e-3});
  const Eigen::VectorXd first = solver.solve_static(none(), load).position_m - model.rest_position_m();
  model.set_youngs_modulus(Eigen::VectorXd::Constant(model.element_count(), 2e6));
  const Eigen::VectorXd second = solver.solve_static(none(), load).position_m - model.rest_position_m();
  EXPECT_LT((second - 0.5 * first).norm(), 1e-6 * first.norm());
  // Softening one half of the bar increases the deflection.
  Eigen::VectorXd youngs = model.youngs_modulus_pa();
  for (int e = 0; e < model.element_count(); ++e) {
    double cx = 0;
    for (int node : model.elements()[static_cast<std::size_t>(e)]) cx += 0.25 * model.rest_position_m()[3 * node];
    if (cx < 5.0) youngs[e] = 1e6;
  }
  model.set_youngs_modulus(youngs);
  const Eigen::VectorXd third = solver.solve_static(none(), load).position_m - model.rest_position_m();
  EXPECT_GT(third.norm(), second.norm() * 1.5);
  EXPECT_LT(third.norm(), first.norm());
}

}  // namespace
}  // namespace pliant::host::test
