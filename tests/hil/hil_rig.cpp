#include "hil_rig.hpp"

#include <algorithm>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/force_torque.hpp"
#include "pliant/hal/gripper.hpp"

namespace pliant::hil {
namespace {

hal::SimulatedObjectConfig shape(hal::ObjectShape kind, int nx, int ny, int nz, double spacing_m, double beta,
                                 double stiffness_n_per_m, double stiffening = 0) {
  hal::SimulatedObjectConfig o;
  o.shape = kind;
  o.nx = nx;
  o.ny = ny;
  o.nz = nz;
  o.spacing_m = spacing_m;
  o.msm_beta = beta;
  o.stiffness_n_per_m = stiffness_n_per_m;
  o.stiffening = stiffening;
  return o;
}

}  // namespace

std::vector<HilObject> hil_objects() {
  using hal::ObjectShape;
  return {
      {"sponge", shape(ObjectShape::box, 6, 5, 4, 0.008, 0.95, 600), 0.15, 60},
      {"foam block", shape(ObjectShape::box, 7, 5, 3, 0.008, 0.85, 900, 1.0), 0.12, 60},
      {"foam cylinder", shape(ObjectShape::cylinder, 3, 0, 4, 0.008, 0.75, 1200), 0.10, 60},
      {"dough ball", shape(ObjectShape::ball, 3, 0, 0, 0.009, 0.65, 1500), 0.08, 60},
      {"gel cube", shape(ObjectShape::box, 5, 5, 5, 0.008, 0.55, 2500), 0.08, 60},
      {"stiffening foam", shape(ObjectShape::box, 5, 4, 3, 0.009, 0.5, 3000, 3.0), 0.10, 60},
      {"ripe fruit", shape(ObjectShape::ball, 3, 0, 0, 0.010, 0.45, 4000), 0.06, 60},
      {"tofu", shape(ObjectShape::box, 6, 4, 4, 0.007, 0.35, 5000), 0.05, 60},
      {"rubber cylinder", shape(ObjectShape::cylinder, 2, 0, 5, 0.009, 0.25, 8000), 0.05, 60},
      {"carton", shape(ObjectShape::box, 8, 5, 3, 0.006, 0.15, 12000), 0.04, 60},
      {"plastic bottle", shape(ObjectShape::cylinder, 3, 0, 3, 0.009, 0.05, 20000), 0.03, 80},
      {"egg", shape(ObjectShape::ball, 2, 0, 0, 0.011, 0.10, 30000), 0.02, 80},
  };
}

SupervisorConfig hil_supervisor_config(const HilObject& object, const RigOptions& options) {
  SupervisorConfig c;
  const double period = 1.0 / options.rate_hz;
  GraspGuardConfig& g = c.guard;
  g.max_strain = (1 - kStrainMargin) * object.max_strain;
  g.max_force_n = object.max_force_n;
  g.prediction_beta_points = options.prediction_beta_points;
  g.prediction_closure_points = options.prediction_closure_points;
  g.contact_force_n = 0.05;  // 10 sd of the gripper's force noise
  // Freshness at the control rate: a 1 kHz source that misses one sample is stale on the next
  // cycle. The camera keeps the default (3 frames at 30 Hz).
  g.gripper_timeout_s = 1.5 * period;
  g.wrench_timeout_s = 1.5 * period;
  g.cycle_timeout_s = 3 * period;
  g.clock_tolerance_s = 0.5 * period;
  g.wrench_frozen_samples = 1;
  // The plant settles between camera frames (hundreds of MSM steps per frame): the estimator's
  // quasi-static row is its form (docs/hil.md, "The estimator's model forms").
  c.estimator.equilibrium_iterations = kEquilibriumIterations;
  // The fault masks stay the guard's defaults: each device's own fault bits plus the stream
  // monitor's flags, which the rig ORs into every sample's status word.
  c.gripper_monitor.max_interval_s = 3 * period;
  c.wrench_monitor.max_interval_s = 3 * period;
  c.camera_monitor.max_interval_s = 3.0 / options.camera_rate_hz;
  c.camera_monitor.max_non_finite_fraction = 0.5;
  return c;
}

Rig::Rig(const HilObject& object, const RigOptions& rig_options) : options(rig_options) {
  hal::SimulatedGraspConfig sim;
  sim.object = object.object;
  sim.period_s = 1.0 / options.rate_hz;
  status = plant.configure(sim);
  if (status != hal::HalStatus::ok) return;
  // The gripper starts pre-positioned, open by pregrasp_gap_m around the object.
  sim.initial_width_m = std::min(sim.max_width_m, plant.extent_m() + options.pregrasp_gap_m);
  status = plant.configure(sim);
  if (status != hal::HalStatus::ok) return;
  hal::MockGripperConfig gc;
  gc.period_s = sim.period_s;
  gc.seed = options.seed;
  hal::MockForceTorqueConfig fc;
  fc.period_s = sim.period_s;
  fc.seed = options.seed + 1;
  hal::MockParticleObserverConfig oc;
  oc.period_s = 1.0 / options.camera_rate_hz;
  oc.noise_m = options.camera_noise_m;
  oc.seed = options.seed + 2;
  gripper = std::make_unique<hal::MockGripper>(plant, clock, gc);
  wrench = std::make_unique<hal::MockForceTorqueSensor>(plant, clock, fc);
  observer = std::make_unique<hal::MockParticleObserver>(plant, clock, oc);
  for (hal::Device* d : {static_cast<hal::Device*>(gripper.get()), static_cast<hal::Device*>(wrench.get()),
                         static_cast<hal::Device*>(observer.get())}) {
    status = d->configure();
    if (status != hal::HalStatus::ok) return;
  }
  supervisor =
      std::make_unique<Supervisor>(*gripper, *wrench, *observer, clock, hil_supervisor_config(object, options));
  status = supervisor->start();
}

const CycleReport& Rig::step() {
  ++cycles;
  // The clock runs on whole periods from its start, so that stamps land on the sample grid.
  (void)clock.set(10.0 + static_cast<double>(cycles) * period_s());
  return supervisor->cycle();
}

}  // namespace pliant::hil
