// fem_locking_bench: how far the linear tetrahedron is from a converged FEM on nearly
// incompressible material, with the volume per element and with the averaged nodal pressure, and
// what the nodal pressure costs.
//
// A plain program (needs the host library). References: CalculiX 2.20, C3D10 quadratic
// tetrahedra, mesh-converged and Richardson-extrapolated (tests/host/data/
// calculix_locking_references.json, made by tools/reference/calculix_locking_references.py).
//
//  1. Bonded cylinder (50 mm across, 30 mm high, both faces bonded, pressed 1 %, linear): the
//     apparent modulus factor F H / (E A delta) on pliant's structured cylinder meshes, A the
//     mesh's own cross-section, against CalculiX. Issue 17's goal: within 3 % on 300-900 nodes.
//  2. Indented block (40 x 40 x 20 mm, bottom bonded, a bonded 10 x 10 mm square punch pressed
//     0.2 mm): on a structured box the punch footprint is only as exact as the grid, so the
//     table compares the rise of the force with nu, F(nu) / F(0.3), which is what locking
//     distorts.
//  3. Cost: one static solve and one backward-Euler step per formulation (wall time, factor
//     entries).
//
// Usage: fem_locking_bench
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pliant/host/fem/cylinder_mesh.hpp"
#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_solver.hpp"

namespace {

using pliant::host::CylinderMeshDivisions;
using pliant::host::TetMesh;
namespace fem = pliant::host::fem;

constexpr double kPi = 3.14159265358979323846;
constexpr double kYoungs = 1e5;
constexpr double kGoal = 0.03;

struct Problem {
  TetMesh mesh;
  std::vector<int> fixed;
  std::vector<int> driven;
  Eigen::VectorXd target;  // driven positions, 3 per driven node
};

fem::FemMaterial material(double nu, fem::FemVolumetric volumetric) {
  fem::FemMaterial m;
  m.youngs_modulus_pa = kYoungs;
  m.poisson_ratio = nu;
  m.density_kg_m3 = 1100;
  m.volumetric = volumetric;
  return m;
}

Problem bonded_cylinder(const CylinderMeshDivisions& divisions) {
  Problem p;
  p.mesh = pliant::host::cylinder_tet_mesh(0.05, 0.03, divisions);
  const int section = p.mesh.point_count() / (divisions.axial + 1);
  for (int i = 0; i < section; ++i) p.fixed.push_back(i);
  for (int i = p.mesh.point_count() - section; i < p.mesh.point_count(); ++i) {
    p.driven.push_back(i);
    p.target.conservativeResize(p.target.size() + 3);
    const double* x = &p.mesh.points[static_cast<std::size_t>(3 * i)];
    p.target.tail<3>() = Eigen::Vector3d(x[0], x[1], x[2] - 0.0003);
  }
  return p;
}

Problem indented_block(int cells_xy, int cells_z) {
  Problem p;
  p.mesh = fem::make_box_tet_mesh(Eigen::Vector3d(0.04, 0.04, 0.02), {cells_xy, cells_xy, cells_z},
                                  fem::BoxSplit::mirrored_kuhn, Eigen::Vector3d(-0.02, -0.02, 0.0));
  for (int i = 0; i < p.mesh.point_count(); ++i) {
    const double* x = &p.mesh.points[static_cast<std::size_t>(3 * i)];
    if (x[2] < 1e-9) {
      p.fixed.push_back(i);
    } else if (x[2] > 0.02 - 1e-9 && std::abs(x[0]) <= 0.005 + 1e-9 && std::abs(x[1]) <= 0.005 + 1e-9) {
      p.driven.push_back(i);
      p.target.conservativeResize(p.target.size() + 3);
      p.target.tail<3>() = Eigen::Vector3d(x[0], x[1], x[2] - 0.0002);
    }
  }
  return p;
}

struct Solved {
  double force_n = 0;
  double seconds = 0;
  std::size_t factor_entries = 0;
};

Solved solve(const Problem& p, double nu, fem::FemVolumetric volumetric) {
  const fem::FemModel model(p.mesh, material(nu, volumetric));
  const auto start = std::chrono::steady_clock::now();
  fem::FemSolver solver(model, p.fixed, p.driven);
  const fem::FemStaticResult result = solver.solve_static(p.target, Eigen::VectorXd());
  Solved out;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.force_n = std::abs(fem::net_force(result.reaction_n, p.driven).z());
  out.factor_entries = solver.factor_entries();
  return out;
}

// Seconds per backward-Euler step (one Newton iteration), pressing the problem's driven nodes.
double step_seconds(const Problem& p, double nu, fem::FemVolumetric volumetric, int steps) {
  const fem::FemModel model(p.mesh, material(nu, volumetric));
  fem::FemSolver solver(model, p.fixed, p.driven);
  fem::FemState state = solver.rest_state();
  Eigen::VectorXd rest(p.target.size());
  for (std::size_t k = 0; k < p.driven.size(); ++k) {
    rest.segment<3>(3 * static_cast<Eigen::Index>(k)) = model.rest_position_m().segment<3>(3 * p.driven[k]);
  }
  const auto start = std::chrono::steady_clock::now();
  for (int s = 1; s <= steps; ++s) {
    const double share = static_cast<double>(s) / steps;
    solver.step(state, 1.0 / 30.0, rest + share * (p.target - rest), Eigen::VectorXd());
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / steps;
}

}  // namespace

int main() {
  std::ifstream file(PLIANT_LOCKING_REFERENCES);
  if (!file) {
    std::fprintf(stderr, "fem_locking_bench: cannot open %s\n", PLIANT_LOCKING_REFERENCES);
    return 1;
  }
  const nlohmann::json doc = nlohmann::json::parse(file);
  std::map<double, double> cylinder_factor;
  std::map<double, double> block_force;
  for (const auto& item : doc.at("cases")) {
    const double nu = item.at("poisson_ratio").get<double>();
    if (item.at("problem") == "bonded_cylinder") cylinder_factor[nu] = item.at("apparent_modulus_factor").get<double>();
    if (item.at("problem") == "indented_block") block_force[nu] = item.at("force_extrapolated_n").get<double>();
  }

  std::printf("1. Bonded cylinder, apparent modulus factor against CalculiX (goal: within %.0f %%)\n", 100 * kGoal);
  std::printf("%-10s %6s %6s %9s %18s %18s\n", "mesh", "nodes", "nu", "CalculiX", "element", "nodal_average");
  const std::vector<CylinderMeshDivisions> meshes = {{2, 16, 6}, {2, 24, 5}, {3, 24, 8}, {3, 32, 8}};
  for (const CylinderMeshDivisions& d : meshes) {
    const Problem p = bonded_cylinder(d);
    const double area = 0.25 * 0.05 * 0.05 * 0.5 * d.circumferential * std::sin(2.0 * kPi / d.circumferential);
    for (const auto& [nu, reference] : cylinder_factor) {
      if (nu < 0.29) continue;
      double factor[2] = {0, 0};
      int column = 0;
      for (fem::FemVolumetric v : {fem::FemVolumetric::element, fem::FemVolumetric::nodal_average}) {
        factor[column++] = solve(p, nu, v).force_n * 0.03 / (kYoungs * area * 0.0003);
      }
      std::printf("%2d,%2d,%-4d %6d %6.3f %9.4f %9.4f (%+5.1f%%) %9.4f (%+5.1f%%)%s\n", d.radial, d.circumferential,
                  d.axial, p.mesh.point_count(), nu, reference, factor[0], 100 * (factor[0] / reference - 1), factor[1],
                  100 * (factor[1] / reference - 1), std::abs(factor[1] / reference - 1) <= kGoal ? "" : "  over goal");
    }
  }

  std::printf("\n2. Indented block, rise of the force with nu, F(nu) / F(0.3), against CalculiX\n");
  std::printf("%-8s %6s %6s %9s %18s %18s\n", "cells", "nodes", "nu", "CalculiX", "element", "nodal_average");
  for (const auto& [cells_xy, cells_z] : std::vector<std::pair<int, int>>{{8, 4}, {16, 8}}) {
    const Problem p = indented_block(cells_xy, cells_z);
    const double base_element = solve(p, 0.3, fem::FemVolumetric::element).force_n;
    const double base_nodal = solve(p, 0.3, fem::FemVolumetric::nodal_average).force_n;
    for (const auto& [nu, reference] : block_force) {
      if (nu < 0.44) continue;
      const double rise = reference / block_force.at(0.3);
      const double element = solve(p, nu, fem::FemVolumetric::element).force_n / base_element;
      const double nodal = solve(p, nu, fem::FemVolumetric::nodal_average).force_n / base_nodal;
      std::printf("%2d,%2d,%-2d %6d %6.3f %9.4f %9.4f (%+5.1f%%) %9.4f (%+5.1f%%)\n", cells_xy, cells_xy, cells_z,
                  p.mesh.point_count(), nu, rise, element, 100 * (element / rise - 1), nodal, 100 * (nodal / rise - 1));
    }
  }

  std::printf("\n3. Cost on the bonded cylinder, nu 0.49 (wall time, one thread)\n");
  std::printf("%-10s %6s %-14s %14s %12s %14s\n", "mesh", "nodes", "formulation", "factor entries", "static (s)",
              "step (ms)");
  for (const CylinderMeshDivisions& d : std::vector<CylinderMeshDivisions>{{2, 24, 5}, {3, 32, 8}}) {
    const Problem p = bonded_cylinder(d);
    for (fem::FemVolumetric v : {fem::FemVolumetric::element, fem::FemVolumetric::nodal_average}) {
      const Solved s = solve(p, 0.49, v);
      std::printf("%2d,%2d,%-4d %6d %-14s %14zu %12.3f %14.2f\n", d.radial, d.circumferential, d.axial,
                  p.mesh.point_count(), fem::to_string(v), s.factor_entries, s.seconds,
                  1e3 * step_seconds(p, 0.49, v, 20));
    }
  }
  return 0;
}
