// Implicit dynamics against what the integrators must do on a linear(ized) structure: free
// vibration in one mode (from modal_analysis) under Newmark conserves energy; under backward
// Euler it decays at the integrator's own rate, damping ratio ~ omega dt / 2 (PHYSICS.md);
// Rayleigh damping decays a mode at zeta = alpha / (2 omega) + beta omega / 2; a damped dynamic
// run settles on the static equilibrium; linear momentum of a free body is conserved.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include <Eigen/Dense>

#include "fem_test_meshes.hpp"
#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/fem/fem_modal.hpp"
#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_solver.hpp"

namespace pliant::host::test {
namespace {

using fem::FemMaterial;
using fem::FemModel;
using fem::FemSolver;

constexpr double kPi = 3.14159265358979323846;

Eigen::VectorXd none() { return Eigen::VectorXd(); }

TetMesh cantilever_mesh() {
  const Eigen::Vector3d size(1.0, 0.1, 0.1);
  const std::array<int, 3> cells = {12, 2, 2};
  return fem::make_box_tet_mesh(size, cells);
}

// A 1 m x 0.1 m x 0.1 m cantilever, clamped at x = 0, with its three lowest modes.
struct Cantilever {
  FemModel model;
  std::vector<int> clamp;
  fem::FemModes modes;

  explicit Cantilever(const FemMaterial& m) : model(cantilever_mesh(), m) {
    for (int i = 0; i < model.node_count(); ++i) {
      if (model.rest_position_m()[3 * i] == 0.0) clamp.push_back(i);
    }
    fem::FemModalOptions options;
    options.mode_count = 3;
    modes = fem::modal_analysis(model, clamp, options);
  }
};

FemMaterial material() {
  FemMaterial m;
  m.youngs_modulus_pa = 1e6;
  m.poisson_ratio = 0.3;
  m.density_kg_m3 = 1000;
  return m;
}

// Decay rate sigma (1/s) of mode `k` started alone at small amplitude and run for `periods`
// periods: least-squares slope of log modal energy, energy = (qdot^2 + omega^2 q^2) / 2 with the
// mass-weighted modal coordinate q = phi^T M (x - X). Also the largest relative change of the
// total (kinetic + elastic) energy over the run.
struct Decay {
  double sigma = 0;
  double energy_drift = 0;
};

Decay run_mode(Cantilever& c, FemSolver& solver, int k, double omega_dt, double periods,
               const fem::FemStepOptions& options) {
  const FemModel& model = c.model;
  const double omega = c.modes.omega_rad_s[k];
  const Eigen::VectorXd phi = c.modes.shape.col(k);
  // Scale: tip amplitude 1e-4 of the length (linear regime).
  const double amplitude = 1e-4 / phi.cwiseAbs().maxCoeff();
  fem::FemState state = solver.rest_state();
  state.position_m += amplitude * phi;
  const double dt = omega_dt / omega;
  const int steps = static_cast<int>(std::ceil(periods * 2 * kPi / omega / dt));
  Eigen::VectorXd mass3(model.dof_count());
  for (int i = 0; i < model.dof_count(); ++i) mass3[i] = model.lumped_mass_kg()[i / 3];
  auto modal_energy = [&](const fem::FemState& s) {
    const double q = phi.dot(mass3.cwiseProduct(s.position_m - model.rest_position_m()));
    const double qdot = phi.dot(mass3.cwiseProduct(s.velocity_m_s));
    return 0.5 * (qdot * qdot + omega * omega * q * q);
  };
  auto total_energy = [&](const fem::FemState& s) {
    return fem::kinetic_energy(model, s.velocity_m_s) + fem::elastic_energy(model, s.position_m);
  };
  const double e0 = total_energy(state);
  Decay out;
  double st = 0, sy = 0, stt = 0, sty = 0;
  for (int n = 0; n <= steps; ++n) {
    if (n > 0) solver.step(state, dt, none(), none(), options);
    const double t = n * dt;
    const double y = std::log(modal_energy(state));
    st += t;
    sy += y;
    stt += t * t;
    sty += t * y;
    out.energy_drift = std::max(out.energy_drift, std::abs(total_energy(state) / e0 - 1));
  }
  const double count = steps + 1;
  out.sigma = -0.5 * (count * sty - st * sy) / (count * stt - st * st);
  return out;
}

TEST(FemDynamics, NewmarkConservesEnergyOfFreeVibration) {
  Cantilever c(material());
  FemSolver solver(c.model, c.clamp, {});
  fem::FemStepOptions options;
  options.integrator = fem::FemIntegrator::newmark;
  options.newton_iterations = 4;
  options.newton_tolerance_m = 1e-15;
  const Decay d = run_mode(c, solver, 0, 0.1, 10, options);
  const double zeta = d.sigma / c.modes.omega_rad_s[0];
  std::printf("Newmark, omega dt = 0.1, 10 periods: zeta %.2e, largest energy change %.2e\n", zeta, d.energy_drift);
  EXPECT_LT(std::abs(zeta), 1e-5);
  EXPECT_LT(d.energy_drift, 1e-6);
}

TEST(FemDynamics, BackwardEulerDampsAtOmegaDtOverTwo) {
  Cantilever c(material());
  FemSolver solver(c.model, c.clamp, {});
  fem::FemStepOptions options;  // backward Euler, one linearization per step
  for (double omega_dt : {0.05, 0.2}) {
    const Decay d = run_mode(c, solver, 0, omega_dt, 4, options);
    const double omega = c.modes.omega_rad_s[0];
    const double dt = omega_dt / omega;
    // Exact for backward Euler on an undamped mode: |z| = 1 / sqrt(1 + (omega dt)^2) per step.
    const double sigma_exact = std::log(1 + omega_dt * omega_dt) / (2 * dt);
    const double zeta = d.sigma / omega;
    std::printf("backward Euler, omega dt = %.2f: zeta %.5f, omega dt / 2 = %.5f, exact discrete %.5f\n", omega_dt,
                zeta, omega_dt / 2, sigma_exact / omega);
    EXPECT_NEAR(d.sigma / sigma_exact, 1.0, 0.02);
    EXPECT_NEAR(zeta / (omega_dt / 2), 1.0, 0.03);
  }
}

TEST(FemDynamics, RayleighDampingMatchesModalFormula) {
  FemMaterial m = material();
  Cantilever probe(m);
  const double omega1 = probe.modes.omega_rad_s[0];
  // zeta_1 = 0.01 from each term.
  m.rayleigh_alpha = 2 * 0.01 * omega1;
  m.rayleigh_beta = 2 * 0.01 / omega1;
  Cantilever c(m);
  FemSolver solver(c.model, c.clamp, {});
  fem::FemStepOptions options;
  options.integrator = fem::FemIntegrator::newmark;
  options.newton_iterations = 3;
  options.newton_tolerance_m = 1e-15;
  for (int k : {0, 1, 2}) {
    const double omega = c.modes.omega_rad_s[k];
    const double expected = m.rayleigh_alpha / (2 * omega) + m.rayleigh_beta * omega / 2;
    const Decay d = run_mode(c, solver, k, 0.05, 6, options);
    std::printf("Rayleigh, mode %d (%.3f Hz): zeta %.5f, alpha/(2w) + beta w/2 = %.5f\n", k + 1,
                c.modes.frequency_hz[k], d.sigma / omega, expected);
    EXPECT_NEAR(d.sigma / omega / expected, 1.0, 0.03) << "mode " << k + 1;
  }
}

TEST(FemDynamics, DampedRunSettlesOnStaticEquilibrium) {
  FemMaterial m = material();
  m.youngs_modulus_pa = 2e7;  // tip sag ~7 % of the length
  m.gravity_m_s2 = Eigen::Vector3d(0, 0, -9.81);
  Cantilever c(m);
  c.model.set_rayleigh(2 * c.modes.omega_rad_s[0], 0.01);
  FemSolver solver(c.model, c.clamp, {});
  const fem::FemStaticResult equilibrium = solver.solve_static(none(), none());
  ASSERT_TRUE(equilibrium.converged);
  const Eigen::VectorXd static_reaction = equilibrium.reaction_n;
  const double sag = (equilibrium.position_m - c.model.rest_position_m()).cwiseAbs().maxCoeff();
  ASSERT_GT(sag, 1e-3);  // a visibly non-linear sag: large rotations at the tip
  for (const fem::FemIntegrator integrator : {fem::FemIntegrator::backward_euler, fem::FemIntegrator::newmark}) {
    fem::FemState state = solver.rest_state();
    fem::FemStepOptions options;
    options.integrator = integrator;
    options.newton_iterations = integrator == fem::FemIntegrator::newmark ? 3 : 1;
    for (int k = 0; k < 600; ++k) solver.step(state, 0.05, none(), none(), options);
    EXPECT_LT((state.position_m - equilibrium.position_m).cwiseAbs().maxCoeff(), 1e-7 * sag);
    // Backward Euler is L-stable: every mode dies out. The average-acceleration rule is not: on
    // stiff, over-damped modes (omega dt >> 1) it leaves a slowly decaying alternating velocity,
    // which still shows in the damping part of the reactions (3e-4 after 600 steps here).
    const double tolerance = integrator == fem::FemIntegrator::backward_euler ? 1e-6 : 1e-3;
    EXPECT_LT((solver.reaction_n() - static_reaction).cwiseAbs().maxCoeff(),
              tolerance * static_reaction.cwiseAbs().maxCoeff());
  }
}

TEST(FemDynamics, FreeBodyConservesLinearMomentum) {
  FemMaterial m = material();
  m.rayleigh_beta = 0.01;  // stiffness-proportional damping exerts no net force
  const TetMesh mesh = ipc_mesh("bar-186.msh");
  const FemModel model(mesh, m);
  FemSolver solver(model, {}, {});
  for (const fem::FemIntegrator integrator : {fem::FemIntegrator::backward_euler, fem::FemIntegrator::newmark}) {
    fem::FemState state = solver.rest_state();
    for (int i = 0; i < model.node_count(); ++i) {
      const Eigen::Vector3d r = model.rest_position_m().segment<3>(3 * i) - Eigen::Vector3d(5, 0.25, 0.5);
      state.velocity_m_s.segment<3>(3 * i) = Eigen::Vector3d(1, -2, 0.5) + Eigen::Vector3d(0.3, 0.1, -0.2).cross(r);
    }
    auto momentum = [&]() {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (int i = 0; i < model.node_count(); ++i)
        p += model.lumped_mass_kg()[i] * state.velocity_m_s.segment<3>(3 * i);
      return p;
    };
    const Eigen::Vector3d p0 = momentum();
    fem::FemStepOptions options;
    options.integrator = integrator;
    for (int k = 0; k < 100; ++k) solver.step(state, 0.01, none(), none(), options);
    EXPECT_LT((momentum() - p0).norm(), 1e-10 * p0.norm());
  }
}

}  // namespace
}  // namespace pliant::host::test
