// A simulated foam-block indentation in the manner of STEPE (Sengupta et al., ICRA 2020): a
// rectangular foam block on a table, a probe pressing the centre of its top face, a depth camera
// that sees the top surface only, and a force sensor on the probe. For testing and benchmarking
// the quasi-static estimators (estimate_static.hpp) against a known Young's modulus and a known
// contact force.
//
// Geometry and frames: the block spans [0, size_x] x [0, size_y] x [0, size_z] (m), z up, the
// bottom face (z = 0) fixed to the table. The estimation mesh (the recording's mesh.vtk) is the
// mirrored-Kuhn box mesh of `cells` (make_box_tet_mesh). The probe footprint is the square of
// +-probe_cells estimation cells in x and y around the top-centre node (so `cells` x and y must be
// even); its estimation nodes are the recording's wrench.applied_to.
//
// Data generation ("truth"): the same corotational FEM, solved statically per frame, on a
// generation mesh that is NOT the estimation mesh by default (no inverse crime): the box with
// cells multiplied by generation_refinement and split as generation_split. Estimation nodes are
// generation nodes (every refinement-th grid point), so tracked positions need no interpolation.
//  * force control: the probe pushes with a uniform pressure over its footprint (consistent nodal
//    loads on the generation mesh's top triangles; or equal nodal shares), total force
//    peak_force_n along the probe direction, ramped linearly: a soft or padded probe.
//  * displacement control: a rigid, bonded flat punch: the generation nodes under the footprint
//    are moved by depth_m along the probe direction, ramped linearly; the measured force is the sum
//    of their reactions.
// Frame 0 is at rest, frames 1..ramp_frames ramp up, then hold_frames frames hold the peak; one
// frame every frame_interval_s. Each frame is a static equilibrium (a slow robot).
//
// Measurements (what a recording carries): particles.csv observes the estimation nodes of the top
// face (z = size_z at rest) except, unless observe_probe, the footprint (the probe hides it),
// with independent Gaussian noise (position_noise_m per coordinate) and optionally gross outliers;
// interior, side and bottom nodes are NaN. wrench.csv holds the probe force (tool on object) and
// its torque about the footprint centre, with Gaussian noise force_noise_n / torque noise
// force_noise_n x 0.01 m. With declare_probe_driven (displacement control only) the footprint nodes
// are driven for the whole recording and observed exactly (the robot's odometry), for the
// displacement-driven estimator. The recording's material declares poisson_ratio and density;
// youngs_modulus is the unknown and is in the truth only. Gravity is not modelled (a foam block's
// weight barely deforms it; leaving it out keeps the force the probe's alone).
//
// Units SI (m, N, Pa, s). Deterministic for a given seed. Host code: allocates, throws
// std::invalid_argument on bad options, std::runtime_error if a generation solve fails.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host::fem {

enum class ProbeControl { force, displacement };

struct StepeScenarioOptions {
  std::string name = "stepe_foam";
  Eigen::Vector3d block_size_m{0.30, 0.20, 0.10};
  /// Estimation mesh: 14 x 10 x 5 cells = 15 x 11 x 6 = 990 nodes, 4200 tetrahedra (STEPE's
  /// foam mechanical mesh had 1049 nodes). x and y must be even (a node at the top centre).
  std::array<int, 3> cells{14, 10, 5};
  /// Generation mesh = cells x this, per axis (>= 1 each): by default 2x finer in x and y
  /// (29 x 21 x 6 = 3654 nodes). {1, 1, 1} with generation_split mirrored_kuhn is the estimation
  /// mesh itself (inverse crime: only noise separates them); {1, 1, 1} with kuhn is the same grid
  /// split differently (cheap, but its local response under a concentrated load differs from the
  /// mirrored split's by up to 15 % on E at large loads: a test of robustness, not of accuracy).
  std::array<int, 3> generation_refinement{2, 2, 1};
  BoxSplit generation_split = BoxSplit::mirrored_kuhn;
  double youngs_modulus_pa = 454e3;  ///< STEPE's foam, ground truth by indentation
  double poisson_ratio = 0.35;       ///< an open-cell foam value (STEPE assumed it known)
  double density_kg_m3 = 30;         ///< declared, irrelevant to statics without gravity
  ProbeControl control = ProbeControl::force;
  /// Footprint half-width in estimation cells: 2 = 5 x 5 estimation nodes, 8.6 x 8 cm (a padded
  /// flat probe; with 1, 3 x 3 nodes, the load of a 4 x 4 cm probe sits mostly on the centre node
  /// of the coarse mesh and the local strain exceeds 50 % at a few hundred newtons).
  int probe_cells = 2;
  /// Force control: the force in equal shares on the footprint's generation nodes (what the
  /// estimators assume) instead of a uniform pressure. With the estimation mesh as generation mesh
  /// this makes the force-driven model exact (for tests of the optimiser alone).
  bool equal_nodal_shares = false;
  /// Probe direction: -z tilted toward +x by this angle (deg), STEPE's "tilted" rows.
  double tilt_deg = 0;
  double peak_force_n = 1000;  ///< force control: about 1.5 cm probe travel
  double depth_m = 0.02;       ///< displacement control: travel along the probe direction
  int ramp_frames = 3;         ///< >= 1
  int hold_frames = 0;         ///< >= 0
  double frame_interval_s = 1.0;
  double position_noise_m = 0.5e-3;  ///< depth-camera tracking noise, per coordinate
  double force_noise_n = 0.2;        ///< force sensor noise, per axis
  /// Gross tracking errors: this many (frame, node) observations, chosen at random among the
  /// observed ones of frames >= 1, displaced by outlier_offset_m in a random direction.
  int outlier_count = 0;
  double outlier_offset_m = 0.03;
  bool observe_probe = false;
  bool declare_probe_driven = false;  ///< displacement control only
  std::uint64_t seed = 1;
};

struct StepeScenario {
  Recording recording;  ///< finalized; write_recording-able
  /// Noise-free probe force (tool on object, N) per frame.
  std::vector<Eigen::Vector3d> true_force_n;
  /// Everything the estimators must not see: E, meshes, per-frame true force and probe travel,
  /// noise levels, outliers injected.
  nlohmann::json truth;
  int generation_nodes = 0;
  int generation_newton_iterations = 0;
  double generation_wall_s = 0;
};

/// Simulates the scenario. Cost: one warm-started static solve per frame on the generation mesh:
/// about 10-15 Newton iterations per frame, each about 0.05 s CPU on the default 3654-node mesh
/// (0.01 s on the 990-node one): 1-3 s for a few frames; deep presses take more iterations.
StepeScenario make_stepe_scenario(const StepeScenarioOptions& options = {});

/// Writes the recording (write_recording) and truth.json beside it into `directory`.
void write_stepe_scenario(const StepeScenario& scenario, const std::string& directory);

}  // namespace pliant::host::fem
