// A recording (docs/spec/recording-v1.md) as an FEM problem: the mesh, the known material, the
// constraints, and per frame the observed node positions, the prescribed positions of the driven
// nodes and the measured wrench. Every FEM estimator starts here, so they all read a recording
// the same way.
//
// Requirements on the recording: dimension 3, length_unit "m", a mesh.vtk (particle i is mesh
// node i). Units SI. 3n vectors are node-major (x y z per node), n = mesh node count.
// Host code: allocates, throws std::invalid_argument with one line naming the cause.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host::fem {

/// What the recording does not say and the FEM needs. Values in recording.json "material"
/// always win over these.
struct FemRecordingDefaults {
  double poisson_ratio = 0.45;  ///< used when material.poisson_ratio is absent
  double density_kg_m3 = 1000;  ///< used when material.density is absent
  /// Young's modulus the model starts from (Pa) when material.youngs_modulus is absent and the
  /// mesh has no per-element values; estimators replace it.
  double youngs_modulus_pa = 1e5;
};

struct FemFrame {
  double time_s = 0;
  Eigen::VectorXd observed_position_m;  ///< 3n; NaN for nodes unobserved in this frame
  std::vector<int> observed_nodes;      ///< ascending ids observed in this frame
  std::vector<int> driven_nodes;        ///< ascending ids driven at this time (their windows)
  /// 3 * driven_nodes.size(): the prescribed positions, in driven_nodes order. Taken from the
  /// node's observation; when the driven node is unobserved in this frame, linearly
  /// interpolated in time between its nearest observed frames (held at the ends).
  Eigen::VectorXd driven_position_m;
  bool has_wrench = false;                                   ///< a wrench sample covers this time
  Eigen::Vector3d wrench_force_n = Eigen::Vector3d::Zero();  ///< interpolated; tool on object
  Eigen::Vector3d wrench_torque_nm = Eigen::Vector3d::Zero();
};

struct FemRecordingProblem {
  std::string name;
  TetMesh mesh;
  FemMaterial material;           ///< from recording.material + defaults (gravity included)
  bool gravity_declared = false;  ///< the recording gave gravity (else zero is assumed)
  /// Names of material parameters the recording declared (estimators keep them fixed).
  std::vector<std::string> known_parameters;
  std::vector<int> fixed_nodes;  ///< ascending
  std::vector<int> applied_to;   ///< wrench.applied_to, ascending (empty without a wrench)
  std::vector<FemFrame> frames;
  bool has_wrench() const { return !applied_to.empty(); }
  bool is_known(const std::string& parameter) const;
};

/// Builds the problem. Throws std::invalid_argument when the recording is 2D, not in metres,
/// has no mesh, or a driven node is never observed inside one of its windows. Wrench samples
/// are interpolated linearly onto frame times; frames outside the wrench's time span have
/// has_wrench = false.
FemRecordingProblem fem_problem_from_recording(const Recording& recording, const FemRecordingDefaults& defaults = {});

/// The frames with time_s <= last_time_s (at least the first frame is kept).
void keep_frames_until(FemRecordingProblem& problem, double last_time_s);

}  // namespace pliant::host::fem
