// fem_bench: one implicit step of the corotational FEM (host library) on bars of ~3000 tetrahedra.
//
// Scene: a silicone-like bar 0.2 x 0.01 x 0.02 m (the IPC bar's proportions) meshed as a
// structured mirrored-Kuhn box of 50 x 2 x 5 cells = 3000 tetrahedra, 918 nodes; E = 1 MPa,
// nu = 0.45, rho = 1100 kg/m^3, Rayleigh alpha 0.5 / s, beta 1e-3 s, gravity -z. The x = 0 face is
// fixed; the x = 0.2 m face is driven up and down (5 mm, 1 Hz) at a 1 kHz step rate. One
// benchmark iteration = one FemSolver::step: element pass (polar decompositions, corotated
// forces, damping product, assembly of M + dt D + dt^2 K into the factor), numeric supernodal
// Cholesky refactorization, solve, state update and reactions at the constrained nodes. The
// same on the IPC mesh bar-2523.msh (2523 tetrahedra, 886 nodes; scaled to the same size), and,
// for information, a static solve and a 6-mode modal analysis of the box.
//
// For comparison with library solvers (why the FEM has its own factorization), the same box's
// backward-Euler matrix M + dt^2 K + dt D on the free DOFs, assembled once, is refactorized and
// solved per iteration by Eigen's SimplicialLLT and, when CHOLMOD is found at build time, by
// CHOLMOD's supernodal LLT through Eigen's CholmodSupport, both with the symbolic analysis done
// once. These time the factorization and solve alone: no element pass and no assembly.
//
// Budget: fem_step/backward_euler/box_3000 <= 3 ms per step.
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/SparseCholesky>
#if PLIANT_BENCH_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include "bench_support.hpp"
#include "fem_test_meshes.hpp"
#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/fem/fem_modal.hpp"
#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_solver.hpp"

namespace pliant::bench {
namespace {

namespace fem = pliant::host::fem;

constexpr double kPi = 3.14159265358979323846;
constexpr double kLength = 0.2;
constexpr double kStepRateHz = 1000;
constexpr int kCycleSteps = 1000;  // 1 Hz

struct FemScene {
  std::string label;
  host::TetMesh mesh;
  std::unique_ptr<fem::FemModel> model;
  std::vector<int> fixed;
  std::vector<int> tool;
  std::unique_ptr<fem::FemSolver> solver;
  fem::FemState state;
  std::vector<Eigen::VectorXd> targets;  // [kCycleSteps] tool positions

  explicit FemScene(const std::string& which) {
    if (which == "box_3000") {
      mesh = fem::make_box_tet_mesh({kLength, 0.01, 0.02}, {50, 2, 5});
    } else {
      mesh = host::test::ipc_mesh("bar-2523.msh");
      for (double& c : mesh.points) c *= kLength / 10.0;
    }
    fem::FemMaterial material;
    material.youngs_modulus_pa = 1e6;
    material.poisson_ratio = 0.45;
    material.density_kg_m3 = 1100;
    material.rayleigh_alpha = 0.5;
    material.rayleigh_beta = 1e-3;
    material.gravity_m_s2 = Eigen::Vector3d(0, 0, -9.81);
    model = std::make_unique<fem::FemModel>(mesh, material);
    fixed = fem::points_on_plane(mesh, 0, 0.0, 1e-9);
    tool = fem::points_on_plane(mesh, 0, kLength, 1e-9);
    solver = std::make_unique<fem::FemSolver>(*model, fixed, tool);
    state = solver->rest_state();
    for (int k = 0; k < kCycleSteps; ++k) {
      Eigen::VectorXd target(3 * static_cast<Eigen::Index>(tool.size()));
      for (std::size_t j = 0; j < tool.size(); ++j) {
        target.segment<3>(3 * static_cast<Eigen::Index>(j)) = model->rest_position_m().segment<3>(3 * tool[j]);
        target[3 * static_cast<Eigen::Index>(j) + 2] += 0.005 * std::sin(2 * kPi * k / kCycleSteps);
      }
      targets.push_back(target);
    }
    label = std::to_string(model->element_count()) + " tets, " + std::to_string(model->node_count()) + " nodes";
  }
};

FemScene& scene_for(const std::string& which) {
  static std::map<std::string, std::unique_ptr<FemScene>> cache;
  auto& slot = cache[which];
  if (!slot) slot = std::make_unique<FemScene>(which);
  return *slot;
}

void BM_FemStep(benchmark::State& bench, const std::string& which, fem::FemIntegrator integrator) {
  FemScene& scene = scene_for(which);
  fem::FemStepOptions options;
  options.integrator = integrator;
  const Eigen::VectorXd no_force;
  const double dt = 1.0 / kStepRateHz;
  int k = 0;
  CpuStopwatch stopwatch;
  stopwatch.start();
  try {
    for (auto _ : bench) {
      scene.solver->step(scene.state, dt, scene.targets[static_cast<std::size_t>(k)], no_force, options);
      if (++k == kCycleSteps) k = 0;
    }
  } catch (const std::exception& e) {
    bench.SkipWithError(e.what());
    return;
  }
  stopwatch.stop();
  if (!scene.state.position_m.allFinite()) {
    bench.SkipWithError("non-finite positions after stepping");
    return;
  }
  const double tets = scene.model->element_count();
  bench.counters["tets"] = tets;
  bench.counters["nodes"] = scene.model->node_count();
  bench.counters["factor_entries"] = static_cast<double>(scene.solver->factor_entries());
  bench.counters["ns_per_tet_step"] = stopwatch.per(static_cast<double>(bench.iterations()) * tets);
  bench.SetLabel(scene.label);
}

void BM_FemStatic(benchmark::State& bench) {
  FemScene& scene = scene_for("box_3000");
  const Eigen::VectorXd no_force;
  int iterations = 0;
  for (auto _ : bench) {
    const fem::FemStaticResult result = scene.solver->solve_static(scene.targets[250], no_force);
    iterations = result.iterations;
    benchmark::DoNotOptimize(result.position_m.data());
  }
  bench.counters["newton_iterations"] = iterations;
  bench.SetLabel(scene.label + ", tool 5 mm up");
}

void BM_FemModal(benchmark::State& bench) {
  FemScene& scene = scene_for("box_3000");
  fem::FemModalOptions options;
  options.mode_count = 6;
  double f1 = 0;
  for (auto _ : bench) {
    const fem::FemModes modes = fem::modal_analysis(*scene.model, scene.fixed, options);
    f1 = modes.frequency_hz[0];
  }
  bench.counters["f1_hz"] = f1;
  bench.SetLabel(scene.label + ", clamped at x = 0");
}

// Backward-Euler system matrix of the box scene at rest on its free DOFs: M + dt (alpha M +
// beta K) + dt^2 K, and a right-hand side (the gravity load).
struct FreeSystem {
  Eigen::SparseMatrix<double> matrix;
  Eigen::VectorXd rhs;
};

FreeSystem free_system(const FemScene& scene, double dt) {
  const fem::FemModel& model = *scene.model;
  const Eigen::SparseMatrix<double> k = fem::stiffness_matrix(model, model.rest_position_m());
  std::vector<int> map(static_cast<std::size_t>(model.dof_count()), 0);
  for (const std::vector<int>* set : {&scene.fixed, &scene.tool}) {
    for (int node : *set) {
      for (int d = 0; d < 3; ++d) map[static_cast<std::size_t>(3 * node + d)] = -1;
    }
  }
  int free = 0;
  for (int& m : map) m = m < 0 ? -1 : free++;
  const double alpha = model.material().rayleigh_alpha;
  const double beta = model.material().rayleigh_beta;
  const double k_scale = dt * dt + dt * beta;
  const double m_scale = 1.0 + dt * alpha;
  std::vector<Eigen::Triplet<double>> triplets;
  for (int col = 0; col < k.outerSize(); ++col) {
    const int c = map[static_cast<std::size_t>(col)];
    if (c < 0) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(k, col); it; ++it) {
      const int r = map[static_cast<std::size_t>(it.row())];
      if (r >= 0) triplets.emplace_back(r, c, k_scale * it.value());
    }
    triplets.emplace_back(c, c, m_scale * model.lumped_mass_kg()[col / 3]);
  }
  FreeSystem system;
  system.matrix.resize(free, free);
  system.matrix.setFromTriplets(triplets.begin(), triplets.end());
  system.rhs = Eigen::VectorXd::Zero(free);
  for (int i = 0; i < model.dof_count(); ++i) {
    const int r = map[static_cast<std::size_t>(i)];
    if (r >= 0 && i % 3 == 2) system.rhs[r] = -9.81 * model.lumped_mass_kg()[i / 3] * dt;
  }
  return system;
}

template <typename Solver>
void BM_LibraryFactorSolve(benchmark::State& bench) {
  FemScene& scene = scene_for("box_3000");
  const FreeSystem system = free_system(scene, 1.0 / kStepRateHz);
  Solver solver;
  solver.analyzePattern(system.matrix);
  Eigen::VectorXd x;
  for (auto _ : bench) {
    solver.factorize(system.matrix);
    x = solver.solve(system.rhs);
    benchmark::DoNotOptimize(x.data());
  }
  if (solver.info() != Eigen::Success || !x.allFinite()) {
    bench.SkipWithError("factorization failed");
    return;
  }
  bench.counters["unknowns"] = static_cast<double>(system.matrix.rows());
  bench.SetLabel(scene.label + ", factor + solve only");
}

void register_all() {
  benchmark::RegisterBenchmark("fem_step/backward_euler/box_3000", BM_FemStep, std::string("box_3000"),
                               fem::FemIntegrator::backward_euler)
      ->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("fem_step/newmark/box_3000", BM_FemStep, std::string("box_3000"),
                               fem::FemIntegrator::newmark)
      ->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("fem_step/backward_euler/ipc_bar_2523", BM_FemStep, std::string("ipc_bar_2523"),
                               fem::FemIntegrator::backward_euler)
      ->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("fem_factor/eigen_simplicial_llt/box_3000",
                               BM_LibraryFactorSolve<Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>>)
      ->Unit(benchmark::kMicrosecond);
#if PLIANT_BENCH_HAVE_CHOLMOD
  benchmark::RegisterBenchmark("fem_factor/cholmod_supernodal_llt/box_3000",
                               BM_LibraryFactorSolve<Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>>>)
      ->Unit(benchmark::kMicrosecond);
#endif
  benchmark::RegisterBenchmark("fem_static/box_3000", BM_FemStatic)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("fem_modal6/box_3000", BM_FemModal)->Unit(benchmark::kMillisecond);
}

}  // namespace
}  // namespace pliant::bench

int main(int argc, char** argv) {
  pliant::bench::register_all();
  const pliant::bench::Budgets budgets = {
      {"fem_step/backward_euler/box_3000", 3000.0},
  };
  return pliant::bench::run_benchmarks(argc, argv, budgets);
}
