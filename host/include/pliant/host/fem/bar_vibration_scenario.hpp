// The synthetic bar of Wang et al. ("Deformation capture and modeling of soft objects", Table 1
// and Fig. 9) as a recording: a cantilever bar deformed by a static load at its free end,
// released at t = 0 and filmed while it rings down. Ground truth for the trajectory estimator
// (estimate_dynamic.hpp) and its benchmark (bench/fem_table1_bench.cpp).
//
// Defaults reproduce the paper's bar: a 20 x 5 x 5 cell box split into 6 tetrahedra per cell
// (mirrored Kuhn split, fem_box_mesh.hpp) has exactly the paper's 3000 tetrahedra, 756 nodes and
// 452 surface vertices. Its size and rate are our choice (the paper gives neither): 0.8 x 0.05 x
// 0.05 m, density 1000 kg/m^3, Poisson ratio 0.4, filmed at 30 Hz (the paper captured with Kinect
// cameras) for 250 frames (8.3 s). With E = 6.8e5 Pa the first bending pair is at about 0.6 Hz,
// so the record holds about 5 periods of it, and the faster modes (second bending ~3.9 Hz,
// torsion) ring down within the first 2-3 s. The low fundamental is deliberate: its decay rate
// is rayleigh_alpha / 2 + rayleigh_beta omega^2 / 2, and at omega ~ 4 rad/s the mass-proportional
// part is most of it, which is what makes rayleigh_alpha identifiable (PHYSICS.md; for a bar half
// as long it is under a fifth, and any small bias in rayleigh_beta then moves rayleigh_alpha by
// several times as much). Gravity is off: this is a synthetic test like the paper's, and a
// horizontal soft bar of this size would sag by more than its length.
//
// Material: control points on the bar's axis at x = (i + 1/2) L / k, i = 0..k-1 (i = 0 next to the
// clamp), with the given moduli, interpolated to the elements by MaterialMap; or, with `slabs`,
// k slabs of equal length with those moduli (a bar of glued blocks: a field no control-point map
// represents exactly). One value gives a uniform bar.
//
// The generated data, and how they avoid the "inverse crime" (the estimator fitting data made
// by its own discretisation): the load is a force and torque spread over the end face
// (add_spread_wrench), scaled so that the largest node displacement of the (nonlinear) static
// response is max_initial_displacement_m (to 1e-4 relative); the static equilibrium under it is frame 0, at rest. Then
// the load is removed and the bar moves freely, integrated with Newmark (average acceleration) at generator_substeps
// substeps per frame (default 32, h = 1 ms) with up to 3 Newton iterations to 1e-9 m, where the estimator steps 4 times
// per frame with one linearised Newton iteration (its time-discretisation error is then what it would be on real data).
// Optional Gaussian noise is added to the observed positions. The mesh itself is shared (a recording carries its mesh;
// PHYSICS.md).
//
// Observation: every surface node in every frame (clamped nodes included); interior nodes are
// NaN (unobserved). Recording: dimension 3, metres, fixed = the clamped face (x = 0), masses =
// the lumped node masses, material = {poisson_ratio, density} (known), mesh.vtk without moduli;
// the truth and the generator settings are written under meta ("truth", "generator") for
// reports only (estimators never read meta).
//
// Host code: allocates, throws std::invalid_argument on bad options. Cost: a few sparse static
// solves plus frame_count * generator_substeps implicit steps of 1-3 Newton iterations (about
// 1-2 min of CPU for the full-size defaults, a few seconds for the reduced bar of the tests).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "pliant/host/fem/material_map.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host::fem {

struct BarVibrationOptions {
  Eigen::Vector3d size_m{0.8, 0.05, 0.05};  ///< x along the bar, clamped at x = 0
  std::array<int, 3> cells{20, 5, 5};       ///< 6 tetrahedra per cell
  double density_kg_m3 = 1000;
  double poisson_ratio = 0.4;
  /// Moduli (Pa) of the k >= 1 control points along the axis (Table 1: {6.8e5}, or the 8-point
  /// bar {1e5, 1e6, 1e4, 6.8e5, 2e6, 7e4, 1e7, 3e4}).
  std::vector<double> control_youngs_modulus_pa{6.8e5};
  MaterialMapOptions material_map;
  /// true: the k moduli are k slabs of equal length along x, piecewise constant (a tetrahedron
  /// takes the modulus of the slab holding its centroid), instead of interpolated by MaterialMap.
  bool slabs = false;
  double rayleigh_alpha = 2.0e-2;  ///< 1/s
  double rayleigh_beta = 1.0e-3;   ///< s

  /// Shape of the initial load on the free end's face: force (N) and torque about the face
  /// centre (N m), both multiplied by one factor so that the static response's largest node
  /// displacement is max_initial_displacement_m (the default bends in z and y and twists).
  Eigen::Vector3d load_force_n{0.0, 0.5, 1.0};
  Eigen::Vector3d load_torque_nm{0.03, 0.0, 0.0};
  double max_initial_displacement_m = 0.08;  ///< > 0 (10 % of the length)

  double frame_rate_hz = 30;  ///< frames at t = f / frame_rate_hz
  int frame_count = 250;      ///< >= 3
  int generator_substeps = 32;
  double noise_m = 0;      ///< standard deviation of Gaussian noise per coordinate (m)
  std::uint64_t seed = 1;  ///< for the noise (std::mt19937_64)
};

struct BarVibrationScenario {
  Recording recording;
  std::vector<Eigen::Vector3d> control_points_m;  ///< on the axis, from the clamp to the tip
  std::vector<double> control_youngs_modulus_pa;  ///< the truth, per control point
  double rayleigh_alpha = 0;
  double rayleigh_beta = 0;
  Eigen::VectorXd element_youngs_modulus_pa;               ///< the truth per tetrahedron
  std::vector<int> clamped_nodes;                          ///< x = 0 face (recording.fixed)
  std::vector<int> tip_nodes;                              ///< x = L face, where the load acted
  Eigen::Vector3d load_force_n = Eigen::Vector3d::Zero();  ///< the scaled load actually applied
  Eigen::Vector3d load_torque_nm = Eigen::Vector3d::Zero();
};

/// Generates the scenario. Throws std::invalid_argument on bad options (non-positive sizes,
/// cells, moduli, rates, counts; negative damping or noise; an all-zero load).
BarVibrationScenario make_bar_vibration_scenario(const BarVibrationOptions& options = {});

/// Surface nodes of a structured box mesh (those on a face of its bounding box).
std::vector<int> box_surface_nodes(const TetMesh& mesh);

}  // namespace pliant::host::fem
