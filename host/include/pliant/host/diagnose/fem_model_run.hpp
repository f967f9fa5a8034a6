// Free-running corotational FEM simulation of a whole recording with every physics knob
// `pliant diagnose --model fem` uses (the FEM counterpart of model_run.hpp).
//
// The recording is read as an FEM problem (fem_recording.hpp): mesh node i is particle i,
// `fixed` nodes are pinned at rest, driven nodes follow their prescribed positions, the wrench
// stream is either a MEASUREMENT or a LOAD:
// - a frame's wrench is a measurement when every applied_to node is constrained (driven or
//   fixed) in that frame: the tool moves those nodes and the load cell reads the force it needs,
//   so the simulated force (the net constraint reaction over applied_to: the tool's force on
//   the object) is compared with it;
// - otherwise it is a load: the measured force (and torque) is spread over the applied_to nodes
//   as an external force, and only positions are compared.
//
// Time: quasi-static (one static equilibrium per solved frame, warm-started from the previous
// solved frame) or dynamic (one Newmark step per frame interval, starting from the static
// equilibrium of frame 0 at rest). In quasi-static mode only every `frame_stride`-th frame is
// solved (always the first and the last); the other frames are NaN in the output. A fit may
// restrict a quasi-static run further to the frames it fits (set_fitting_frames).
//
// Effects (FemRunSettings; each is off at its default):
// - stiffening k: element modulus E_e = E f_e exp(k eps_e^2) (exponential, Fung-type strain
//   stiffening; k eps^2 capped at 12), eps_e the equivalent (von Mises) Biot strain
//   sqrt(2/3) |dev(S - I)| of the element's polar decomposition F = R S at the current
//   solution. Static frames solve for positions and consistent moduli together (Newton steps
//   with the moduli updated from the current strains, Anderson-accelerated); dynamic steps use
//   the strains at the start of the step.
// - relaxation (relaxation_fraction g, relaxation_time_s tau): quasi-linear viscoelasticity of
//   the simulated force, f(t) = f_el(t) + g int exp(-(t - s) / tau) d f_el(s); the instantaneous
//   modulus is (1 + g) E, the long-term one E. Only the force output changes (with displacement
//   drives and a uniform relaxing modulus the equilibrium positions do not change).
// - extra_rayleigh_beta: stiffness-proportional damping added to the declared one (dynamic).
// - plasticity (plastic_yield, plastic_creep): after each solved frame the rest position of
//   every non-fixed node whose largest adjacent element strain exceeds the yield creeps toward
//   its current position (the body's rigid motion removed) at rate plastic_creep (1/s).
// - wrench_latency_s tau: the wrench stream lags the positions by tau: the predicted
//   measurement at t is the simulated force at t - tau (measurements), or the load applied at
//   t is the stream's value at t + tau (loads).
// - extra_gravity: a body acceleration added to the declared gravity.
// - element_factor: per-element modulus factors (heterogeneity).
// - support_friction mu (friction): the fixed nodes, when they lie on one plane, are not pins but
//   contacts on that plane. They keep their distance to it (bonded in the normal direction: no
//   lift-off) and slide in it under Coulomb's law: a support node sticks while the tangential
//   force holding it is at most mu times the normal force pressing it on the plane, and slips
//   with exactly that force, against its motion, once it would exceed it (no normal force: it
//   slides freely). Static frames and dynamic steps are solved with the supports held at
//   trial positions; the slips are found on the stiffness condensed onto the supports
//   (fem_condensation.hpp) by projected Gauss-Seidel, and the full model is solved again until
//   the slips change by less than 1e-6 of the object's size (at most 25 rounds). A slip is
//   permanent: the next frame starts from where the supports ended.
//
// Units SI (m, s, N, Pa). Host code: allocates; throws std::invalid_argument from the
// constructor when the recording cannot be an FEM problem, never from simulate() (a failed
// solve gives ok = false).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pliant/host/recording.hpp"

namespace pliant::host {

struct FemRunSettings {
  double youngs_modulus_pa = 1e5;
  Eigen::Vector3d extra_gravity_m_s2 = Eigen::Vector3d::Zero();
  double stiffening = 0;           ///< k in E exp(k eps^2) (dimensionless); 0: linear material
  double relaxation_fraction = 0;  ///< g; 0: no relaxation
  double relaxation_time_s = 1;
  double extra_rayleigh_beta = 0;      ///< s; dynamic mode only
  double plastic_yield = 0;            ///< equivalent strain
  double plastic_creep = 0;            ///< 1/s; 0: no plasticity
  double wrench_latency_s = 0;         ///< s; positive: the wrench stream lags
  std::vector<double> element_factor;  ///< per element; empty: 1 everywhere
  double support_friction = -1;        ///< Coulomb mu of the support plane; < 0: pinned supports
};

enum class FemTimeMode { quasi_static, dynamic };

struct FemRun {
  bool ok = true;
  std::string failure;  ///< why ok is false
  /// Recording::positions layout (frame-major, [(frame * n + id) * 3 + axis]); NaN in frames
  /// that were not solved.
  std::vector<double> positions;
  /// [frame * 3 + axis]: the predicted wrench-stream force (tool on object, N) in frames where
  /// the wrench is a measurement and the frame was solved; NaN elsewhere.
  std::vector<double> force;
};

class FemRecordingSimulator {
 public:
  /// Throws std::invalid_argument when the recording is not an FEM problem (not 3D, not in
  /// metres, no mesh) or holds the body against nothing (no fixed or driven node).
  FemRecordingSimulator(const Recording& recording, FemTimeMode mode, int frame_stride);
  ~FemRecordingSimulator();
  FemRecordingSimulator(const FemRecordingSimulator&) = delete;
  FemRecordingSimulator& operator=(const FemRecordingSimulator&) = delete;

  /// fitting_only: solve only the frames set_fitting_frames() chose (quasi-static runs; a dynamic
  /// run steps through every frame regardless). Exact for effects without history (the static
  /// equilibrium of a frame does not depend on the others), not for relaxation, latency or
  /// plasticity, whose force or rest shape at a frame depends on the frames before it.
  FemRun simulate(const FemRunSettings& settings, bool fitting_only = false);
  /// The frames simulate(settings, true) solves: those marked here and in solved(), plus the
  /// first solved frame. Unset: all solved frames.
  void set_fitting_frames(const std::vector<unsigned char>& frames);

  FemTimeMode mode() const;
  /// 1 for every frame that simulate() solves (positions and forces finite there).
  const std::vector<unsigned char>& solved() const;
  /// 1 for frames whose wrench is a measurement (compared with the simulated force).
  const std::vector<unsigned char>& force_measured() const;
  /// The measured wrench force per frame [frame * 3 + axis] (NaN where no sample covers it).
  const std::vector<double>& measured_force() const;
  /// True when some frame applies the wrench as a load.
  bool has_load() const;
  /// True when the positions do not depend on E and the force is proportional to it, so E can
  /// be profiled in closed form: quasi-static, no body force, no wrench load.
  bool scale_invariant(const FemRunSettings& settings) const;
  /// True when the run depends on E only through the body acceleration over E (quasi-static, no
  /// wrench load): the run at (c E, c g) is the run at (E, g) with every force times c and the
  /// same positions, so E can be profiled in closed form at a fixed ratio g / E.
  bool scale_invariant_at_fixed_gravity_ratio() const;
  /// True when the fixed nodes span one plane (at least three, not on a line, off the plane by
  /// at most 1e-3 of their extent): the supports can then slide (FemRunSettings::support_friction).
  bool has_support_plane() const;
  /// Unit normal of the support plane, pointing from it into the body (zero without a plane).
  Eigen::Vector3d support_normal() const;
  /// Declared body acceleration (m/s^2; zero when the recording declares none).
  Eigen::Vector3d declared_gravity_m_s2() const;
  /// Declared material (from recording.material, else the defaults of fem_recording.hpp).
  double poisson_ratio() const;
  double density_kg_m3() const;
  /// Declared Young's modulus, or 0 when the recording declares none.
  double declared_youngs_modulus_pa() const;
  bool gravity_declared() const;
  int element_count() const;
  /// Element centroids at rest (3 per element).
  std::vector<double> element_centroids() const;
  /// Lowest natural period (s) of the free nodes with fixed and frame-0 driven nodes clamped, at
  /// Young's modulus E; infinity when it cannot be computed.
  double lowest_period_s(double youngs_modulus_pa) const;
  /// Time scale of the loading (s): largest travel of a driven node from its rest (or largest
  /// measured load) divided by its largest rate between frames; infinity when nothing moves.
  double loading_time_s() const;

 private:
  struct ElasticRun {
    bool ok = true;
    std::string failure;
    std::vector<double> positions;
    std::vector<int> force_frames;  // solved frames whose wrench is a measurement
    std::vector<double> force_times;
    std::vector<Eigen::Vector3d> elastic;  // net constraint force over applied_to
  };
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pliant::host
