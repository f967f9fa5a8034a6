// fem_convergence: mesh-convergence table of the corotational FEM against beam theory.
//
// A plain program (not Google Benchmark; needs the host library). The bar meshes of IPC
// (examples/meshes/tetmesh_ipc, a 10 x 0.5 x 1 box, read as metres) and their uniform 1:8
// refinements, plus structured mirrored-Kuhn boxes of the same bar, are clamped at x = 0 (every
// node of that face fixed) and loaded at x = 10 by a tip force spread over the end face in
// proportion to its area (a uniform traction). Material E = 1 MPa, nu = 0 (Euler-Bernoulli has no
// Poisson effect, and with nu = 0 the clamp does not restrain lateral strain), rho = 1000 kg/m^3.
//
// For each bending direction (z: thickness 1 m, y: thickness 0.5 m) it prints the tip deflection
// (area-weighted mean over the end face, small load so the response is linear) against
// Euler-Bernoulli delta = F L^3 / (3 E I), and the first bending frequency (lumped mass, modal
// analysis) against f1 = 1.8751^2 / (2 pi) sqrt(E I / (rho A L^4)). Timoshenko's shear
// correction for this slenderness is +0.6 % deflection (z) and +0.15 % (y), and shear plus
// rotary inertia lower f1 by roughly 0.5 % (z) and 0.1 % (y): beam theory itself is good to
// that level, so "error" below is against Euler-Bernoulli, with that caveat.
//
// Usage: fem_convergence [--levels N]   (refinement levels of bar-2523 and of the boxes; default 2)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "fem_test_meshes.hpp"
#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/fem/fem_modal.hpp"
#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_solver.hpp"

namespace {

using pliant::host::TetMesh;
namespace fem = pliant::host::fem;

constexpr double kLength = 10.0;
constexpr double kWidthY = 0.5;
constexpr double kHeightZ = 1.0;
constexpr double kYoungs = 1e6;
constexpr double kDensity = 1000;
constexpr double kPi = 3.14159265358979323846;
constexpr double kBeta1 = 1.87510406871196;  // first root of cos(b) cosh(b) = -1

struct Row {
  std::string name;
  int tets = 0;
  int nodes = 0;
  double deflection[2] = {0, 0};  // z, y
  double f1[2] = {0, 0};
  double seconds = 0;      // wall
  double cpu_seconds = 0;  // process CPU
};

Row study(const std::string& name, const TetMesh& mesh) {
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  fem::FemMaterial material;
  material.youngs_modulus_pa = kYoungs;
  material.poisson_ratio = 0.0;
  material.density_kg_m3 = kDensity;
  const fem::FemModel model(mesh, material);
  const std::vector<int> clamp = fem::points_on_plane(mesh, 0, 0.0, 1e-9);
  const std::vector<double> weight = pliant::host::test::face_area_weights(model, 0, kLength);
  double tip_area = 0;
  for (double w : weight) tip_area += w;
  fem::FemSolver solver(model, clamp, {});
  Row row;
  row.name = name;
  row.tets = model.element_count();
  row.nodes = model.node_count();
  const double load = 1e-3;  // N: deflections ~1e-5 of the length, linear regime
  for (int k = 0; k < 2; ++k) {
    const int axis = k == 0 ? 2 : 1;
    Eigen::VectorXd force = Eigen::VectorXd::Zero(model.dof_count());
    for (int i = 0; i < model.node_count(); ++i) {
      force[3 * i + axis] = -load * weight[static_cast<std::size_t>(i)] / tip_area;
    }
    fem::FemStaticOptions options;
    options.residual_tolerance_n = 1e-5 * load;  // linear regime: one factorization
    const fem::FemStaticResult result = solver.solve_static(Eigen::VectorXd(), force, options);
    double mean = 0;
    for (int i = 0; i < model.node_count(); ++i) {
      mean += weight[static_cast<std::size_t>(i)] *
              (result.position_m[3 * i + axis] - model.rest_position_m()[3 * i + axis]);
    }
    row.deflection[k] = -mean / tip_area / load;  // compliance, m/N
  }
  fem::FemModalOptions options;
  options.mode_count = 3;
  const fem::FemModes modes = fem::modal_analysis(model, clamp, options);
  // First bending mode in each direction: the lowest mode whose motion is mostly along it.
  for (int k = 0; k < 2; ++k) {
    const int axis = k == 0 ? 2 : 1;
    for (int m = 0; m < modes.shape.cols(); ++m) {
      double along = 0;
      double total = 0;
      for (int i = 0; i < model.node_count(); ++i) {
        along += std::pow(modes.shape(3 * i + axis, m), 2);
        total += modes.shape.col(m).segment<3>(3 * i).squaredNorm();
      }
      if (along > 0.5 * total) {
        row.f1[k] = modes.frequency_hz[m];
        break;
      }
    }
  }
  row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  row.cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  int levels = 2;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--levels") == 0 && i + 1 < argc) {
      levels = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: fem_convergence [--levels N]\n");
      return 1;
    }
  }
  const double area = kWidthY * kHeightZ;
  const double inertia[2] = {kWidthY * std::pow(kHeightZ, 3) / 12.0, kHeightZ * std::pow(kWidthY, 3) / 12.0};
  double eb_compliance[2];
  double eb_f1[2];
  for (int k = 0; k < 2; ++k) {
    eb_compliance[k] = std::pow(kLength, 3) / (3.0 * kYoungs * inertia[k]);
    eb_f1[k] = kBeta1 * kBeta1 / (2 * kPi) * std::sqrt(kYoungs * inertia[k] / (kDensity * area * std::pow(kLength, 4)));
  }
  std::printf("Cantilever 10 x 0.5 x 1 m, E = 1 MPa, nu = 0, rho = 1000 kg/m^3, clamped at x = 0, tip traction.\n");
  std::printf("Euler-Bernoulli: z-bending tip compliance %.6g m/N, f1 %.6g Hz; y-bending %.6g m/N, f1 %.6g Hz\n\n",
              eb_compliance[0], eb_f1[0], eb_compliance[1], eb_f1[1]);
  std::printf("%-22s %8s %7s | %12s %8s %10s %8s | %12s %8s %10s %8s | %7s %7s\n", "mesh", "tets", "nodes",
              "defl z m/N", "err z", "f1 z Hz", "err", "defl y m/N", "err y", "f1 y Hz", "err", "wall s", "cpu s");
  auto print = [&](const Row& r) {
    std::printf("%-22s %8d %7d | %12.6g %+7.2f%% %10.6g %+7.2f%% | %12.6g %+7.2f%% %10.6g %+7.2f%% | %7.2f %7.2f\n",
                r.name.c_str(), r.tets, r.nodes, r.deflection[0], 100 * (r.deflection[0] / eb_compliance[0] - 1),
                r.f1[0], 100 * (r.f1[0] / eb_f1[0] - 1), r.deflection[1],
                100 * (r.deflection[1] / eb_compliance[1] - 1), r.f1[1], 100 * (r.f1[1] / eb_f1[1] - 1), r.seconds,
                r.cpu_seconds);
    std::fflush(stdout);
  };
  for (const char* name : {"bar-6.msh", "bar-186.msh", "bar-651.msh", "bar-2523.msh"}) {
    print(study(name, pliant::host::test::ipc_mesh(name)));
  }
  TetMesh mesh = pliant::host::test::ipc_mesh("bar-2523.msh");
  for (int level = 1; level <= levels; ++level) {
    mesh = fem::refine_tet_mesh(mesh);
    print(study("bar-2523.msh /" + std::to_string(1 << level) + " (x" + std::to_string(1 << (3 * level)) + ")", mesh));
  }
  std::printf("\nStructured mirrored-Kuhn boxes (6 tets per cell):\n");
  for (int level = 0; level <= levels + 1; ++level) {
    const int s = 1 << level;
    const std::array<int, 3> cells = {20 * s, 1 * s, 2 * s};
    const TetMesh box = fem::make_box_tet_mesh({kLength, kWidthY, kHeightZ}, cells);
    print(study("box " + std::to_string(cells[0]) + "x" + std::to_string(cells[1]) + "x" + std::to_string(cells[2]),
                box));
  }
  return 0;
}
