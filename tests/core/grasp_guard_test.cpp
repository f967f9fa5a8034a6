// The grasp guard's verdicts: every reason reachable and clearing with hysteresis, faults not ok
// within one cycle, no chatter near thresholds, the slip cue bounded by the object's limit,
// stop actions, the force model, contact detection and init validation.
//
// The rig: a 2D block (8 x 5 particles at 5 mm, 35 mm across the jaws) squeezed at 1 kHz; the
// gripper reports a linear spring (1 N at contact + 2 N/mm), the wrist a steady load with
// 1e-4 N of noise, the camera a strain of 0.01 captured 20 ms earlier, the estimator
// msm_beta 0.4 +- 0.02. Every source delivers a new sample each cycle unless a test holds it.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "grasp_guard_fixture.hpp"

namespace pliant {
namespace {

using test::GuardedObject;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

bool has(const GraspGuardOutput& out, GuardReason reason) {
  return (out.reasons & (1u << static_cast<unsigned>(reason))) != 0;
}
std::string describe(const GraspGuardOutput& out) {
  std::string text = std::string(grasp_verdict_name(out.verdict)) + "/" + guard_reason_name(out.reason) + " [";
  for (int r = 1; r < kGuardReasonCount; ++r) {
    if ((out.reasons & (1u << static_cast<unsigned>(r))) != 0)
      text += std::string(guard_reason_name(static_cast<GuardReason>(r))) + " ";
  }
  return text + "]";
}

GraspGuardConfig rig_config() {
  GraspGuardConfig config;
  config.max_strain = 0.1;
  config.max_force_n = 10;
  config.nominal_force_n = 5;
  config.prediction_beta_points = 6;
  config.prediction_closure_points = 16;
  return config;
}

struct Rig {
  static constexpr double kContactWidth = 0.040;
  static constexpr double kStiffness = 2000;  // N/m
  static constexpr double kPreload = 1.0;     // N at contact

  GuardedObject<2, double> object{test::lattice<2, double>(8, 5, 1, 0.005)};
  Status status = Status::not_initialized;
  GraspGuardInput in;
  GraspGuardOutput out;
  double t = 100.0;
  long cycle_count = 0;
  bool fresh[kGuardSourceCount] = {true, true, true, true, true};
  bool live_wrench = true;  ///< false: new stamps, bit-identical values (a frozen sensor)
  double closure = 0;

  /// touch: one cycle at closure 0 first, so contact (and closure 0) is at kContactWidth.
  explicit Rig(const GraspGuardConfig& config = rig_config(), bool touch = true) {
    status = object.build_guard(config);
    in.gripper.valid = true;
    in.wrench.valid = true;
    in.deformation.valid = true;
    in.estimate.valid = true;
    const double load[6] = {0.1, 0.2, -3.0, 0.01, 0.02, 0.0};
    for (int d = 0; d < 6; ++d) in.wrench.wrench[d] = load[d];
    in.deformation.strain = 0.01;
    in.estimate.msm_beta = 0.4;
    in.estimate.msm_beta_std = 0.02;
    squeeze(0);
    if (touch && status == Status::ok) cycle();
  }
  GraspGuard<2, double>& guard() { return object.guard; }

  /// Gripper at `c` past contact, with the spring's force.
  void squeeze(double c) {
    closure = c;
    in.gripper.width_m = kContactWidth - c;
    in.gripper.force_n = kPreload + kStiffness * c;
  }
  void hold(GuardSource source) { fresh[static_cast<int>(source)] = false; }
  void resume(GuardSource source) { fresh[static_cast<int>(source)] = true; }

  const GraspGuardOutput& cycle(double dt = 0.001) {
    ++cycle_count;
    t += dt;
    in.now_s = t;
    if (fresh[0]) in.gripper.stamp_s = t;
    if (fresh[1]) {
      in.wrench.stamp_s = t;
      if (live_wrench) in.wrench.wrench[0] = 0.1 + 1e-4 * std::sin(0.37 * static_cast<double>(cycle_count));  // noise
    }
    if (fresh[2]) in.deformation.stamp_s = t - 0.02;
    if (fresh[3]) in.estimate.stamp_s = t;
    EXPECT_EQ(grasp_guard_update(object.guard, in, out), Status::ok);
    return out;
  }
  /// Runs n cycles and returns how many were not ok.
  int run(int n) {
    int bad = 0;
    for (int i = 0; i < n; ++i) bad += cycle().verdict != GraspVerdict::ok ? 1 : 0;
    return bad;
  }
};

TEST(GraspGuard, NominalGraspIsOkAndReportsThePrediction) {
  Rig rig;
  ASSERT_EQ(rig.status, Status::ok);
  EXPECT_EQ(rig.run(30), 0) << describe(rig.out);
  rig.squeeze(0.001);
  const GraspGuardOutput& out = rig.cycle();
  EXPECT_EQ(out.verdict, GraspVerdict::ok) << describe(out);
  EXPECT_EQ(out.reason, GuardReason::none);
  EXPECT_TRUE(out.in_contact);
  EXPECT_DOUBLE_EQ(out.contact_width_m, Rig::kContactWidth);
  EXPECT_NEAR(out.closure_m, 0.001, 1e-12);
  EXPECT_NEAR(out.beta_low, 0.36, 1e-12);
  EXPECT_NEAR(out.beta_high, 0.44, 1e-12);
  EXPECT_DOUBLE_EQ(out.strain_safe_closure_m, grasp_guard_strain_safe_closure(rig.guard(), 0.36, 0.44));
  EXPECT_GT(out.strain_safe_closure_m, 0.001);
  EXPECT_LE(out.safe_closure_m, out.strain_safe_closure_m);
  EXPECT_NEAR(out.safe_width_m, Rig::kContactWidth - out.safe_closure_m, 1e-15);
  EXPECT_DOUBLE_EQ(out.allowed_force_n, 5.0);
  EXPECT_GT(out.predicted_strain, 0.0);
  EXPECT_LT(out.predicted_strain, 0.1);
  EXPECT_EQ(rig.guard().counters.cycles, 32u);
  EXPECT_EQ(rig.guard().counters.limit_cycles + rig.guard().counters.stop_cycles, 0u);
}

TEST(GraspGuard, UninitialisedGuardStops) {
  GraspGuard<2, double> guard;
  GraspGuardInput in;
  GraspGuardOutput out;
  out.verdict = GraspVerdict::ok;
  EXPECT_EQ(grasp_guard_update(guard, in, out), Status::not_initialized);
  EXPECT_EQ(out.verdict, GraspVerdict::stop);
  EXPECT_EQ(out.reason, GuardReason::not_configured);
  EXPECT_EQ(out.stop_action, StopAction::freeze);
}

// --- faults --------------------------------------------------------------------------------------

struct Fault {
  const char* name;
  std::function<void(Rig&)> inject;
  std::function<void(Rig&)> repair;
  GuardReason reason;
  GuardSource source;
};

void age(Rig& rig, GuardSource source, int cycles) {
  rig.hold(source);
  for (int i = 0; i < cycles; ++i) rig.cycle();
}

std::vector<Fault> faults() {
  auto nothing = [](Rig&) {};
  auto restore_width = [](Rig& r) { r.squeeze(r.closure); };
  auto restore_wrench = [](Rig& r) { r.in.wrench.wrench[2] = -3.0; };
  return {
      {"nan width", [](Rig& r) { r.in.gripper.width_m = kNaN; }, restore_width, GuardReason::nan_input,
       GuardSource::gripper},
      {"inf force", [](Rig& r) { r.in.gripper.force_n = kInf; }, restore_width, GuardReason::nan_input,
       GuardSource::gripper},
      {"nan gripper stamp",
       [](Rig& r) {
         r.hold(GuardSource::gripper);
         r.in.gripper.stamp_s = kNaN;
       },
       [](Rig& r) { r.resume(GuardSource::gripper); }, GuardReason::nan_input, GuardSource::gripper},
      {"nan wrench Fz", [](Rig& r) { r.in.wrench.wrench[2] = kNaN; }, restore_wrench, GuardReason::nan_input,
       GuardSource::wrench},
      {"nan torque", [](Rig& r) { r.in.wrench.wrench[4] = kNaN; }, [](Rig& r) { r.in.wrench.wrench[4] = 0.02; },
       GuardReason::nan_input, GuardSource::wrench},
      {"nan strain", [](Rig& r) { r.in.deformation.strain = kNaN; }, [](Rig& r) { r.in.deformation.strain = 0.01; },
       GuardReason::nan_input, GuardSource::camera},
      {"nan beta", [](Rig& r) { r.in.estimate.msm_beta = kNaN; }, [](Rig& r) { r.in.estimate.msm_beta = 0.4; },
       GuardReason::nan_input, GuardSource::estimate},
      {"nan beta sd", [](Rig& r) { r.in.estimate.msm_beta_std = kNaN; },
       [](Rig& r) { r.in.estimate.msm_beta_std = 0.02; }, GuardReason::nan_input, GuardSource::estimate},
      {"gripper invalid", [](Rig& r) { r.in.gripper.valid = false; }, [](Rig& r) { r.in.gripper.valid = true; },
       GuardReason::invalid_input, GuardSource::gripper},
      {"negative width", [](Rig& r) { r.in.gripper.width_m = -0.001; }, restore_width, GuardReason::invalid_input,
       GuardSource::gripper},
      {"width in mm", [](Rig& r) { r.in.gripper.width_m = 40.0; }, restore_width, GuardReason::invalid_input,
       GuardSource::gripper},
      {"future gripper stamp",
       [](Rig& r) {
         r.hold(GuardSource::gripper);
         r.in.gripper.stamp_s = r.t + 1.0;
       },
       [](Rig& r) { r.resume(GuardSource::gripper); }, GuardReason::invalid_input, GuardSource::gripper},
      {"wrench invalid", [](Rig& r) { r.in.wrench.valid = false; }, [](Rig& r) { r.in.wrench.valid = true; },
       GuardReason::invalid_input, GuardSource::wrench},
      {"negative strain", [](Rig& r) { r.in.deformation.strain = -0.2; },
       [](Rig& r) { r.in.deformation.strain = 0.01; }, GuardReason::invalid_input, GuardSource::camera},
      {"beta above 1", [](Rig& r) { r.in.estimate.msm_beta = 1.2; }, [](Rig& r) { r.in.estimate.msm_beta = 0.4; },
       GuardReason::invalid_input, GuardSource::estimate},
      {"estimate invalid", [](Rig& r) { r.in.estimate.valid = false; }, [](Rig& r) { r.in.estimate.valid = true; },
       GuardReason::invalid_input, GuardSource::estimate},
      {"gripper fault code", [](Rig& r) { r.in.gripper.status_bits = 0x0eu << 8; },
       [](Rig& r) { r.in.gripper.status_bits = 0; }, GuardReason::sensor_fault, GuardSource::gripper},
      {"ATI supply low", [](Rig& r) { r.in.wrench.status_bits = 1u << 5; }, [](Rig& r) { r.in.wrench.status_bits = 0; },
       GuardReason::sensor_fault, GuardSource::wrench},
      {"camera status", [](Rig& r) { r.in.deformation.status_bits = 1; },
       [](Rig& r) { r.in.deformation.status_bits = 0; }, GuardReason::sensor_fault, GuardSource::camera},
      {"gripper bus off", [](Rig& r) { r.in.gripper.bus_off = true; }, [](Rig& r) { r.in.gripper.bus_off = false; },
       GuardReason::bus_off, GuardSource::gripper},
      {"F/T bus off", [](Rig& r) { r.in.wrench.bus_off = true; }, [](Rig& r) { r.in.wrench.bus_off = false; },
       GuardReason::bus_off, GuardSource::wrench},
      {"camera bus off", [](Rig& r) { r.in.deformation.bus_off = true; },
       [](Rig& r) { r.in.deformation.bus_off = false; }, GuardReason::bus_off, GuardSource::camera},
      {"Modbus timeout", [](Rig& r) { r.in.gripper.timeout = true; }, [](Rig& r) { r.in.gripper.timeout = false; },
       GuardReason::timeout, GuardSource::gripper},
      {"F/T timeout", [](Rig& r) { r.in.wrench.timeout = true; }, [](Rig& r) { r.in.wrench.timeout = false; },
       GuardReason::timeout, GuardSource::wrench},
      {"camera timeout", [](Rig& r) { r.in.deformation.timeout = true; },
       [](Rig& r) { r.in.deformation.timeout = false; }, GuardReason::timeout, GuardSource::camera},
      // Stale: the source stops delivering; the injection runs the cycles up to its timeout
      // (20, 20, 80 past the camera's 20 ms latency, 500 ms), so the checked cycle is 1 ms past it.
      {"stale gripper", [](Rig& r) { age(r, GuardSource::gripper, 20); },
       [](Rig& r) { r.resume(GuardSource::gripper); }, GuardReason::stale_gripper, GuardSource::gripper},
      {"stale wrench", [](Rig& r) { age(r, GuardSource::wrench, 20); }, [](Rig& r) { r.resume(GuardSource::wrench); },
       GuardReason::stale_wrench, GuardSource::wrench},
      {"stale camera", [](Rig& r) { age(r, GuardSource::camera, 80); }, [](Rig& r) { r.resume(GuardSource::camera); },
       GuardReason::stale_camera, GuardSource::camera},
      {"stale estimate", [](Rig& r) { age(r, GuardSource::estimate, 500); },
       [](Rig& r) { r.resume(GuardSource::estimate); }, GuardReason::stale_estimate, GuardSource::estimate},
      {"nan clock", [](Rig& r) { r.in.now_s = kNaN; }, nothing, GuardReason::nan_input, GuardSource::clock},
  };
}

// Every fault makes the verdict not ok in the very cycle it first appears, with its reason and
// source and the source's configured verdict; after the repair it stays for clear_samples - 1
// samples and clears on the clear_samples-th.
TEST(GraspGuard, EveryFaultIsNotOkWithinOneCycleAndClearsWithHysteresis) {
  for (const Fault& fault : faults()) {
    SCOPED_TRACE(fault.name);
    Rig rig;
    ASSERT_EQ(rig.status, Status::ok);
    rig.squeeze(0.0005);
    ASSERT_EQ(rig.run(20), 0) << describe(rig.out);
    fault.inject(rig);
    GraspGuardOutput out;
    if (fault.source == GuardSource::clock) {
      // The rig sets now_s itself; feed the guard the bad clock directly.
      rig.in.now_s = kNaN;
      ASSERT_EQ(grasp_guard_update(rig.guard(), rig.in, out), Status::ok);
    } else {
      out = rig.cycle();
    }
    const GraspVerdict expected = rig.guard().config.fault_verdict[static_cast<int>(fault.source)];
    EXPECT_EQ(out.verdict, expected) << describe(out);
    EXPECT_TRUE(has(out, fault.reason)) << describe(out);
    EXPECT_EQ(out.reason, fault.reason) << describe(out);
    EXPECT_NE(out.fault_sources & (1u << static_cast<unsigned>(fault.source)), 0u);
    if (expected == GraspVerdict::stop) {
      EXPECT_EQ(out.stop_action, StopAction::freeze);
    }
    // It persists while the fault does (a few more cycles).
    if (fault.source != GuardSource::clock) {
      for (int i = 0; i < 3; ++i) EXPECT_TRUE(has(rig.cycle(), fault.reason)) << describe(rig.out);
    }
    fault.repair(rig);
    const int needed = rig.guard().config.clear_samples;
    for (int i = 1; i < needed; ++i) {
      EXPECT_TRUE(has(rig.cycle(), fault.reason)) << "cleared after " << i << " samples: " << describe(rig.out);
    }
    EXPECT_EQ(rig.cycle().verdict, GraspVerdict::ok) << describe(rig.out);
    const auto source = static_cast<std::size_t>(fault.source);
    EXPECT_GT(rig.guard().counters.refused[source] + rig.guard().counters.stale_cycles[source], 0u);
  }
}

// Staleness is judged against each source's own timeout: ok while the age is within it, not ok
// in the first cycle after.
TEST(GraspGuard, StaleWithinOneCycleOfTheTimeout) {
  struct Case {
    GuardSource source;
    double timeout;
    GuardReason reason;
  };
  for (const Case& c : {Case{GuardSource::gripper, 0.02, GuardReason::stale_gripper},
                        Case{GuardSource::wrench, 0.02, GuardReason::stale_wrench},
                        Case{GuardSource::camera, 0.1, GuardReason::stale_camera},
                        Case{GuardSource::estimate, 0.5, GuardReason::stale_estimate}}) {
    SCOPED_TRACE(guard_source_name(c.source));
    Rig rig;
    ASSERT_EQ(rig.run(10), 0);
    const double age0 = c.source == GuardSource::camera ? 0.02 : 0.0;  // the camera's capture latency
    rig.hold(c.source);
    const int ok_cycles = static_cast<int>(std::floor((c.timeout - age0) * 1000 + 1e-9)) - 1;
    for (int i = 0; i < ok_cycles; ++i)
      ASSERT_EQ(rig.cycle().verdict, GraspVerdict::ok) << i << " " << describe(rig.out);
    rig.cycle();  // at the timeout itself, either is right
    EXPECT_TRUE(has(rig.cycle(), c.reason)) << describe(rig.out);
    EXPECT_NE(rig.out.verdict, GraspVerdict::ok);
  }
}

TEST(GraspGuard, ClockFaults) {
  Rig rig;
  ASSERT_EQ(rig.run(10), 0);
  // A cycle 25 ms after the last (cycle_timeout_s 20 ms): timeout on the clock, stop/freeze.
  const GraspGuardOutput& late = rig.cycle(0.025);
  EXPECT_EQ(late.verdict, GraspVerdict::stop) << describe(late);
  EXPECT_EQ(late.reason, GuardReason::timeout);
  EXPECT_NE(late.fault_sources & (1u << static_cast<unsigned>(GuardSource::clock)), 0u);
  EXPECT_EQ(late.stop_action, StopAction::freeze);
  rig.run(5);
  EXPECT_EQ(rig.cycle().verdict, GraspVerdict::ok) << describe(rig.out);
  // Time going backwards.
  rig.t -= 0.01;
  EXPECT_TRUE(has(rig.cycle(), GuardReason::invalid_input)) << describe(rig.out);
  EXPECT_EQ(rig.out.verdict, GraspVerdict::stop);
}

// A status bit outside the fault mask (ATI bit 0: watchdog reset) is not a fault.
TEST(GraspGuard, StatusBitsOutsideTheMaskAreIgnored) {
  Rig rig;
  rig.in.wrench.status_bits = 1u;
  EXPECT_EQ(rig.run(20), 0) << describe(rig.out);
  rig.in.wrench.status_bits = 1u << 14;  // CAN bus error: transport degraded, not sensor invalid
  EXPECT_EQ(rig.run(5), 0) << describe(rig.out);
}

// With the default masks, a gripper's state bits (activated, moving, object detected, at
// target) and a camera's partial frame are not faults; every fault-code value, every stream
// monitor flag except the sequence gap, and the frame's device fault are.
TEST(GraspGuard, DefaultMasksTellStatesFromFaults) {
  Rig rig;
  rig.in.gripper.status_bits = 0x0fu;
  rig.in.deformation.status_bits = 1u << 1;
  rig.in.wrench.status_bits = 1u << 16;
  EXPECT_EQ(rig.run(20), 0) << describe(rig.out);
  for (std::uint32_t code = 1; code <= 0xff; code += 0x11) {
    rig.in.gripper.status_bits = 0x0fu | code << 8;
    EXPECT_TRUE(has(rig.cycle(), GuardReason::sensor_fault)) << code << " " << describe(rig.out);
    EXPECT_EQ(rig.out.fault_sources, 1u << static_cast<unsigned>(GuardSource::gripper)) << code;
  }
  rig.in.gripper.status_bits = 0x0fu;
  for (unsigned bit = 17; bit <= 21; ++bit) {
    rig.in.wrench.status_bits = 1u << bit;
    EXPECT_TRUE(has(rig.cycle(), GuardReason::sensor_fault)) << bit << " " << describe(rig.out);
    EXPECT_NE(rig.out.fault_sources & (1u << static_cast<unsigned>(GuardSource::wrench)), 0u) << bit;
  }
  rig.in.wrench.status_bits = 0;
  rig.in.deformation.status_bits = 1u;
  EXPECT_TRUE(has(rig.cycle(), GuardReason::sensor_fault)) << describe(rig.out);
  EXPECT_NE(rig.out.fault_sources & (1u << static_cast<unsigned>(GuardSource::camera)), 0u);
}

TEST(GraspGuard, BackwardsStampIsInvalid) {
  Rig rig;
  ASSERT_EQ(rig.run(10), 0);
  rig.hold(GuardSource::wrench);
  rig.in.wrench.stamp_s = rig.t - 0.005;  // older than the last sample seen
  EXPECT_TRUE(has(rig.cycle(), GuardReason::invalid_input)) << describe(rig.out);
  EXPECT_EQ(rig.out.verdict, GraspVerdict::stop);
}

TEST(GraspGuard, FrozenWrenchIsStale) {
  GraspGuardConfig config = rig_config();
  config.wrench_frozen_samples = 10;
  Rig rig(config);
  ASSERT_EQ(rig.run(20), 0);
  rig.live_wrench = false;  // the driver keeps stamping new samples; the values repeat bit for bit
  for (int i = 1; i < 10; ++i) EXPECT_FALSE(has(rig.cycle(), GuardReason::stale_wrench)) << i;
  EXPECT_TRUE(has(rig.cycle(), GuardReason::stale_wrench)) << describe(rig.out);
  EXPECT_EQ(rig.out.verdict, GraspVerdict::stop);
  rig.live_wrench = true;
  EXPECT_EQ(rig.run(4), 4);
  EXPECT_EQ(rig.cycle().verdict, GraspVerdict::ok) << describe(rig.out);
  // Off by default: a frozen wrench alone is then no fault.
  Rig lenient;
  lenient.live_wrench = false;
  EXPECT_EQ(lenient.run(100), 0);
}

// --- limits ---------------------------------------------------------------------------------------

struct Limit {
  const char* name;
  std::function<void(GraspGuardConfig&)> configure;
  std::function<void(Rig&)> cross;   ///< just past the threshold
  std::function<void(Rig&)> within;  ///< inside the hysteresis band: must not clear
  std::function<void(Rig&)> below;   ///< below threshold x (1 - margin): clears
  GuardReason reason;
  GraspVerdict verdict;
  StopAction action;
  GuardReason after;  ///< what remains once it cleared (an exceeded limit leaves its limit)
};

std::vector<Limit> limits() {
  auto none = [](GraspGuardConfig&) {};
  // The spring: F = 1 + 2000 c. nominal 5 N at c = 2 mm, max 10 N x 1.1 = 11 N at c = 5 mm.
  auto force_at = [](double f) { return [f](Rig& r) { r.squeeze((f - Rig::kPreload) / Rig::kStiffness); }; };
  auto strain_at = [](double e) { return [e](Rig& r) { r.in.deformation.strain = e; }; };
  auto closure_at = [](double c) { return [c](Rig& r) { r.squeeze(c); }; };
  return {
      {"force limit", none, force_at(5.001), force_at(4.8), force_at(4.7), GuardReason::force_limit,
       GraspVerdict::limit, StopAction::freeze, GuardReason::none},
      {"force exceeded", [](GraspGuardConfig& c) { c.max_strain = kInf; }, force_at(11.01), force_at(10.5),
       force_at(10.4), GuardReason::force_exceeded, GraspVerdict::stop, StopAction::open, GuardReason::force_limit},
      {"strain limit", none, strain_at(0.1001), strain_at(0.096), strain_at(0.094), GuardReason::strain_limit,
       GraspVerdict::limit, StopAction::freeze, GuardReason::none},
      {"strain exceeded", none, strain_at(0.1101), strain_at(0.106), strain_at(0.104), GuardReason::strain_exceeded,
       GraspVerdict::stop, StopAction::open, GuardReason::strain_limit},
      {"indentation limit", [](GraspGuardConfig& c) { c.max_indentation_m = 0.0015; }, closure_at(0.00151),
       closure_at(0.00144), closure_at(0.00142), GuardReason::indentation_limit, GraspVerdict::limit,
       StopAction::freeze, GuardReason::none},
      {"indentation exceeded",
       [](GraspGuardConfig& c) {
         c.max_indentation_m = 0.001;
         c.nominal_force_n = 10;
       },
       closure_at(0.00111), closure_at(0.00106), closure_at(0.00104), GuardReason::indentation_exceeded,
       GraspVerdict::stop, StopAction::open, GuardReason::indentation_limit},
      {"estimate uncertain (limit)", [](GraspGuardConfig& c) { c.uncertain_estimate_verdict = GraspVerdict::limit; },
       [](Rig& r) { r.in.estimate.msm_beta_std = 0.16; }, [](Rig& r) { r.in.estimate.msm_beta_std = 0.145; },
       [](Rig& r) { r.in.estimate.msm_beta_std = 0.14; }, GuardReason::estimate_uncertain, GraspVerdict::limit,
       StopAction::freeze, GuardReason::none},
      {"estimate uncertain (sd infinite)",
       [](GraspGuardConfig& c) { c.uncertain_estimate_verdict = GraspVerdict::stop; },
       [](Rig& r) { r.in.estimate.msm_beta_std = kInf; }, [](Rig& r) { r.in.estimate.msm_beta_std = 0.149; },
       [](Rig& r) { r.in.estimate.msm_beta_std = 0.02; }, GuardReason::estimate_uncertain, GraspVerdict::stop,
       StopAction::freeze, GuardReason::none},
  };
}

// Each limit: reached in the cycle its measure crosses the threshold, held while the measure is
// inside the hysteresis band (however long), and cleared only after clear_samples samples below
// threshold x (1 - margin).
TEST(GraspGuard, EveryLimitIsReachableAndClearsWithHysteresis) {
  for (const Limit& limit : limits()) {
    SCOPED_TRACE(limit.name);
    GraspGuardConfig config = rig_config();
    limit.configure(config);
    Rig rig(config);
    ASSERT_EQ(rig.status, Status::ok);
    rig.squeeze(0.0003);
    ASSERT_EQ(rig.run(20), 0) << describe(rig.out);
    limit.cross(rig);
    const GraspGuardOutput& out = rig.cycle();
    EXPECT_EQ(out.verdict, limit.verdict) << describe(out);
    EXPECT_EQ(out.reason, limit.reason) << describe(out);
    if (limit.verdict == GraspVerdict::stop) {
      EXPECT_EQ(out.stop_action, limit.action);
    }
    EXPECT_EQ(out.fault_sources, 0u);
    limit.within(rig);
    for (int i = 0; i < 50; ++i) ASSERT_TRUE(has(rig.cycle(), limit.reason)) << "cleared inside the band at " << i;
    limit.below(rig);
    for (int i = 1; i < config.clear_samples; ++i) EXPECT_TRUE(has(rig.cycle(), limit.reason)) << i;
    rig.cycle();
    EXPECT_FALSE(has(rig.out, limit.reason)) << describe(rig.out);
    EXPECT_EQ(rig.out.reason, limit.after) << describe(rig.out);
    EXPECT_EQ(rig.out.verdict, limit.after == GuardReason::none ? GraspVerdict::ok : GraspVerdict::limit);
  }
}

// Closing past the MSM-predicted safe closure: predicted_strain (limit), before any measured
// strain or force limit; it clears once the jaws back off below safe x (1 - margin).
TEST(GraspGuard, PredictedStrainLimitsClosure) {
  GraspGuardConfig config = rig_config();
  config.max_force_n = 100;
  config.nominal_force_n = 100;
  Rig rig(config);
  ASSERT_EQ(rig.run(10), 0);
  const double safe = grasp_guard_strain_safe_closure(rig.guard(), 0.36, 0.44);
  ASSERT_GT(safe, 0.0005);
  rig.squeeze(0.99 * safe);
  EXPECT_EQ(rig.cycle().verdict, GraspVerdict::ok) << describe(rig.out);
  EXPECT_LE(rig.out.predicted_strain, 0.1);
  rig.squeeze(1.001 * safe);
  EXPECT_EQ(rig.cycle().verdict, GraspVerdict::limit) << describe(rig.out);
  EXPECT_EQ(rig.out.reason, GuardReason::predicted_strain);
  // The reported strain agrees with the refined crossing: past the limit one sub-step on.
  const double resolution = rig.guard().closure_step_m / config.prediction_refine_steps;
  rig.squeeze(safe + resolution);
  EXPECT_GE(rig.cycle().predicted_strain, 0.1);
  rig.squeeze(1.001 * safe);
  rig.squeeze(0.97 * safe);
  EXPECT_EQ(rig.run(50), 50);  // inside the band
  rig.squeeze(0.9 * safe);
  EXPECT_EQ(rig.run(config.clear_samples - 1), config.clear_samples - 1);
  EXPECT_EQ(rig.cycle().verdict, GraspVerdict::ok) << describe(rig.out);
  // The same closure is past the prediction when the estimate says nothing: the whole beta range.
  rig.in.estimate.msm_beta_std = kInf;
  rig.squeeze(1.001 * grasp_guard_strain_safe_closure(rig.guard(), 0.0, 1.0));
  EXPECT_EQ(rig.cycle().reason, GuardReason::predicted_strain) << describe(rig.out);
  EXPECT_DOUBLE_EQ(rig.out.beta_low, 0.0);
  EXPECT_DOUBLE_EQ(rig.out.beta_high, 1.0);
  EXPECT_TRUE(has(rig.out, GuardReason::estimate_uncertain));  // informational by default
}

// Noise near a threshold, smaller than the hysteresis band: exactly one transition. The control
// run without hysteresis chatters, so the check can fail.
TEST(GraspGuard, NoChatterNearThresholds) {
  auto transitions = [](const GraspGuardConfig& config, bool force) {
    Rig rig(config);
    EXPECT_EQ(rig.status, Status::ok);
    rig.squeeze(0.0003);
    rig.run(20);
    int changes = 0;
    GraspVerdict last = rig.out.verdict;
    std::uint64_t state = 12345;
    for (int i = 0; i < 3000; ++i) {
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;
      const double u = static_cast<double>(state >> 11) / 9007199254740992.0 * 2 - 1;  // [-1, 1)
      const double ramp = std::min(1.0, i / 500.0);  // approach, then sit at the threshold
      if (force) {
        const double f = (4.0 + 1.0 * ramp) * (1 + 0.02 * u);
        rig.squeeze((f - Rig::kPreload) / Rig::kStiffness);
      } else {
        rig.in.deformation.strain = (0.08 + 0.02 * ramp) * (1 + 0.02 * u);
      }
      if (rig.cycle().verdict != last) ++changes;
      last = rig.out.verdict;
    }
    return changes;
  };
  for (bool force : {true, false}) {
    SCOPED_TRACE(force ? "force" : "strain");
    EXPECT_EQ(transitions(rig_config(), force), 1);
    GraspGuardConfig bare = rig_config();
    bare.hysteresis_margin = 0;
    bare.clear_samples = 1;
    EXPECT_GT(transitions(bare, force), 20) << "the control without hysteresis should chatter";
  }
}

// --- slip -------------------------------------------------------------------------------------------

// A 40 Hz force jitter at the wrist (slip) raises the allowed force at slip_force_rate_per_s,
// and never above max_force_n; a slow load change is no slip; nothing is raised before contact
// or from a stale wrench; a new grasp restores the nominal force.
TEST(GraspGuard, SlipRaisesTheAllowedForceOnlyUpToTheObjectsLimit) {
  GraspGuardConfig config = rig_config();
  config.max_force_n = 6;
  config.nominal_force_n = 4;
  Rig rig(config, false);
  ASSERT_EQ(rig.status, Status::ok);
  // Whole periods from phase 0, so no step at the start or end (a step is a slip-like transient).
  auto jitter = [&](int cycles, double amplitude, double hz) {
    double highest = 0;
    for (int i = 0; i < cycles; ++i) {
      rig.in.wrench.wrench[1] = 0.2 + amplitude * std::sin(2 * 3.14159265358979 * hz * i * 1e-3);
      rig.cycle();
      highest = std::max(highest, rig.out.allowed_force_n);
      EXPECT_LE(rig.out.allowed_force_n, config.max_force_n);
    }
    return highest;
  };
  // Before contact: the gripper reports no force.
  rig.in.gripper.force_n = 0;
  rig.in.gripper.width_m = 0.06;
  EXPECT_DOUBLE_EQ(jitter(200, 1.0, 40), 4.0);
  EXPECT_FALSE(rig.out.slip);
  EXPECT_DOUBLE_EQ(jitter(300, 0.0, 40), 4.0);  // let the high-pass settle
  // In contact, steady: no slip. A slow (0.5 Hz) 0.2 N load swing passes the 5 Hz high-pass at
  // a tenth, under the 0.048 N floor: no slip either.
  rig.squeeze(0.0005);
  EXPECT_DOUBLE_EQ(jitter(300, 0.0, 40), 4.0);
  EXPECT_DOUBLE_EQ(jitter(2000, 0.2, 0.5), 4.0);
  EXPECT_FALSE(rig.out.slip);
  // Slip: 100 ms of jitter raises the allowed force, by at most the rate allows.
  const double raised = jitter(100, 0.5, 40);  // 4 periods
  EXPECT_GT(raised, 4.1);
  EXPECT_LE(raised, 4.0 * std::exp(config.slip_force_rate_per_s * 0.1) + 1e-9);
  EXPECT_GT(rig.guard().counters.slip_cycles, 50u);
  // A grip force between nominal and the raised allowance is no longer a force limit.
  rig.squeeze((0.5 * (4.0 + raised) - Rig::kPreload) / Rig::kStiffness);
  EXPECT_EQ(rig.cycle().verdict, GraspVerdict::ok) << describe(rig.out);
  // Sustained slip: clamped exactly at the object's limit, never above.
  EXPECT_DOUBLE_EQ(jitter(3000, 0.5, 40), 6.0);  // 120 periods
  EXPECT_DOUBLE_EQ(rig.out.allowed_force_n, 6.0);
  // A stale wrench raises nothing.
  GraspGuardConfig config2 = config;
  Rig stale(config2);
  stale.squeeze(0.0005);
  stale.run(20);
  stale.hold(GuardSource::wrench);
  for (int i = 0; i < 100; ++i) {
    stale.in.wrench.wrench[1] = 0.2 + 0.5 * std::sin(2 * 3.14159265358979 * 40 * i * 1e-3);
    stale.cycle();
    EXPECT_DOUBLE_EQ(stale.out.allowed_force_n, 4.0);
  }
  // A new grasp restores the nominal force.
  grasp_guard_reset(rig.guard());
  rig.in.wrench.wrench[1] = 0.2;
  rig.cycle();
  EXPECT_DOUBLE_EQ(rig.out.allowed_force_n, 4.0);
}

// --- actions, force model, contact -------------------------------------------------------------------

TEST(GraspGuard, StopActionsAndLatching) {
  // A fault and an exceeded limit together: the exceeded limit dominates and opens.
  Rig rig;
  rig.squeeze(0.0003);
  ASSERT_EQ(rig.run(10), 0);
  rig.in.deformation.strain = 0.2;
  rig.in.wrench.bus_off = true;
  rig.cycle();
  EXPECT_EQ(rig.out.verdict, GraspVerdict::stop);
  EXPECT_EQ(rig.out.reason, GuardReason::strain_exceeded);
  EXPECT_EQ(rig.out.stop_action, StopAction::open);
  EXPECT_TRUE(has(rig.out, GuardReason::bus_off));
  // Configurable: freeze on exceeded, open on faults.
  GraspGuardConfig config = rig_config();
  config.exceeded_stop_action = StopAction::freeze;
  config.fault_stop_action = StopAction::open;
  config.latch_stop = true;
  Rig latched(config);
  latched.squeeze(0.0003);
  ASSERT_EQ(latched.run(10), 0);
  latched.in.gripper.bus_off = true;
  latched.cycle();
  EXPECT_EQ(latched.out.stop_action, StopAction::open);
  latched.in.gripper.bus_off = false;
  latched.run(50);
  EXPECT_EQ(latched.out.verdict, GraspVerdict::stop) << "latch_stop: held until acknowledged";
  EXPECT_EQ(latched.out.reason, GuardReason::bus_off);
  grasp_guard_acknowledge_stop(latched.guard());
  EXPECT_EQ(latched.cycle().verdict, GraspVerdict::ok) << describe(latched.out);
  latched.in.deformation.strain = 0.3;
  latched.cycle();
  EXPECT_EQ(latched.out.stop_action, StopAction::freeze);
  latched.in.deformation.strain = 0.01;
  latched.run(50);
  EXPECT_EQ(latched.out.reason, GuardReason::strain_exceeded);
  grasp_guard_reset(latched.guard());
  EXPECT_EQ(latched.cycle().verdict, GraspVerdict::ok) << describe(latched.out);
}

// A linear spring: the fitted stiffness is the spring's, the force-limited closure is where the
// spring reaches the allowed force, and the predicted force at the safe closure is the spring's.
TEST(GraspGuard, ForceModelFromTheMeasuredSpring) {
  GraspGuardConfig config = rig_config();
  config.max_strain = kInf;  // only the force bounds the closure
  config.nominal_force_n = 4;
  Rig rig(config);
  ASSERT_EQ(rig.run(5), 0);
  for (int i = 0; i <= 100; ++i) {
    rig.squeeze(1e-5 * i);  // 1 mm at 10 um per cycle
    rig.cycle();
  }
  EXPECT_EQ(rig.out.verdict, GraspVerdict::ok) << describe(rig.out);
  // The preload makes the secant (3 N / 1 mm) steeper than the tangent (2 N/mm): the larger wins.
  EXPECT_NEAR(rig.out.stiffness_n_per_m, (Rig::kPreload + Rig::kStiffness * 0.001) / 0.001, 1e-6);
  const double k = rig.out.stiffness_n_per_m;
  EXPECT_NEAR(rig.out.force_safe_closure_m, 0.001 + (4.0 - 3.0) / k, 1e-12);
  EXPECT_DOUBLE_EQ(rig.out.safe_closure_m, rig.out.force_safe_closure_m);
  EXPECT_NEAR(rig.out.predicted_force_n, 4.0, 1e-9);
  // A stiffening contact, F = 0.5 N + 3e6 N/m^2 c^2: the latest segment's slope (about 5.3 N/mm
  // over 0.83-0.94 mm; the true tangent at 1 mm is 6) exceeds the secant (3.5 N/mm) and the
  // window's mean slope (3.5 N/mm, around 0.6 mm), and is used.
  Rig stiffening(config, false);
  for (int i = 0; i <= 100; ++i) {
    const double c = 1e-5 * i;
    stiffening.in.gripper.width_m = Rig::kContactWidth - c;
    stiffening.in.gripper.force_n = 0.5 + 3e6 * c * c;
    stiffening.cycle();
  }
  EXPECT_GT(stiffening.out.stiffness_n_per_m, 3500 * 1.2);
  EXPECT_LT(stiffening.out.stiffness_n_per_m, 6000);
  // Force model off below force_model_min_closure_m.
  Rig early(config);
  early.squeeze(0.0001);
  early.run(5);
  EXPECT_NEAR(early.out.closure_m, 0.0001, 1e-15);
  EXPECT_TRUE(std::isnan(early.out.predicted_force_n));
  EXPECT_TRUE(std::isinf(early.out.force_safe_closure_m));
}

TEST(GraspGuard, MotorCurrentForceSource) {
  GraspGuardConfig config = rig_config();
  config.force_source = ForceSource::motor_current;
  config.current_gain_n_per_a = 20;
  config.current_offset_a = 0.1;
  Rig rig(config, false);
  ASSERT_EQ(rig.status, Status::ok);
  rig.in.gripper.force_n = kNaN;  // unused
  rig.in.gripper.current_a = 0.1 + 4.0 / 20;
  EXPECT_EQ(rig.run(5), 0) << describe(rig.out);
  EXPECT_NEAR(rig.out.force_n, 4.0, 1e-12);
  rig.in.gripper.current_a = 0.1 + 5.5 / 20;
  EXPECT_EQ(rig.cycle().reason, GuardReason::force_limit);
  rig.in.gripper.current_a = kNaN;
  EXPECT_EQ(rig.cycle().reason, GuardReason::nan_input);
}

// Contact: detected at the first force >= contact_force_n (closure 0 before); a contact width
// far from the model's extent (a unit error, the wrong object) is not_configured until reset.
TEST(GraspGuard, ContactDetectionAndGeometryCheck) {
  Rig rig(rig_config(), false);
  rig.in.gripper.width_m = 0.05;
  rig.in.gripper.force_n = 0.2;
  EXPECT_EQ(rig.run(5), 0);
  EXPECT_FALSE(rig.out.in_contact);
  EXPECT_DOUBLE_EQ(rig.out.closure_m, 0.0);
  EXPECT_TRUE(std::isnan(rig.out.safe_width_m));
  rig.in.gripper.width_m = 0.041;
  rig.in.gripper.force_n = 0.6;
  rig.cycle();
  EXPECT_TRUE(rig.out.in_contact);
  EXPECT_DOUBLE_EQ(rig.out.contact_width_m, 0.041);
  rig.in.gripper.width_m = 0.0405;
  EXPECT_NEAR(rig.cycle().closure_m, 0.0005, 1e-15);

  Rig wrong(rig_config(), false);
  wrong.in.gripper.width_m = 0.012;  // 12 mm against a 35 mm model
  wrong.in.gripper.force_n = 1.0;
  wrong.cycle();
  EXPECT_EQ(wrong.out.verdict, GraspVerdict::stop);
  EXPECT_EQ(wrong.out.reason, GuardReason::not_configured);
  EXPECT_EQ(wrong.run(20), 20);
  grasp_guard_reset(wrong.guard());
  wrong.in.gripper.width_m = 0.05;
  wrong.in.gripper.force_n = 0;
  EXPECT_EQ(wrong.cycle().verdict, GraspVerdict::ok) << describe(wrong.out);

  // A configured contact width.
  GraspGuardConfig config = rig_config();
  config.contact_width_m = 0.039;
  Rig fixed(config, false);
  fixed.in.gripper.width_m = 0.0385;
  fixed.cycle();
  EXPECT_TRUE(fixed.out.in_contact);
  EXPECT_NEAR(fixed.out.closure_m, 0.0005, 1e-15);
}

// Faults of the camera and the estimator hold (limit) by default; every fault verdict is
// configurable, but never to ok.
TEST(GraspGuard, FaultVerdictsPerSource) {
  GraspGuardConfig config = rig_config();
  config.fault_verdict[static_cast<int>(GuardSource::camera)] = GraspVerdict::stop;
  config.fault_verdict[static_cast<int>(GuardSource::gripper)] = GraspVerdict::limit;
  Rig rig(config);
  ASSERT_EQ(rig.run(10), 0);
  rig.in.deformation.strain = kNaN;
  EXPECT_EQ(rig.cycle().verdict, GraspVerdict::stop);
  rig.in.deformation.strain = 0.01;
  rig.run(10);
  rig.in.gripper.valid = false;
  EXPECT_EQ(rig.cycle().verdict, GraspVerdict::limit);
  GraspGuardConfig bad = rig_config();
  bad.fault_verdict[static_cast<int>(GuardSource::wrench)] = GraspVerdict::ok;
  Rig refused(bad);
  EXPECT_EQ(refused.status, Status::invalid_argument);
}

// --- init -------------------------------------------------------------------------------------------

TEST(GraspGuardInit, RejectsBadConfigurations) {
  std::vector<std::function<void(GraspGuardConfig&)>> breakers = {
      [](GraspGuardConfig& c) { c.max_strain = 0; },
      [](GraspGuardConfig& c) { c.max_strain = kNaN; },
      [](GraspGuardConfig& c) { c.max_force_n = kInf; },
      [](GraspGuardConfig& c) { c.nominal_force_n = 20; },
      [](GraspGuardConfig& c) { c.gripper_timeout_s = 0; },
      [](GraspGuardConfig& c) { c.cycle_timeout_s = kNaN; },
      [](GraspGuardConfig& c) { c.hysteresis_margin = 1; },
      [](GraspGuardConfig& c) { c.clear_samples = 0; },
      [](GraspGuardConfig& c) { c.stop_overshoot = -0.1; },
      [](GraspGuardConfig& c) { c.confidence_k = -1; },
      [](GraspGuardConfig& c) { c.slip_ceiling_n = 0.01; },
      [](GraspGuardConfig& c) { c.force_fit_forgetting = 0; },
      [](GraspGuardConfig& c) { c.prediction_beta_points = 1; },
      [](GraspGuardConfig& c) { c.prediction_closure_points = 1; },
      [](GraspGuardConfig& c) { c.prediction_max_closure_m = 0.05; },  // past the object's extent
      [](GraspGuardConfig& c) { c.relax_max_iterations = 0; },
      [](GraspGuardConfig& c) { c.force_source = ForceSource::motor_current; },  // no gain
      [](GraspGuardConfig& c) { c.contact_width_m = 0.2; },                      // far from the 35 mm model
  };
  for (std::size_t i = 0; i < breakers.size(); ++i) {
    GraspGuardConfig config = rig_config();
    breakers[i](config);
    GuardedObject<2, double> object(test::lattice<2, double>(8, 5, 1, 0.005));
    EXPECT_EQ(object.build_guard(config), Status::invalid_argument) << "breaker " << i;
    EXPECT_FALSE(object.guard.initialized());
  }
}

TEST(GraspGuardInit, RejectsModelsAndObjectsItCannotSqueeze) {
  // A fixed particle (a support) fights the jaws; a particle that is not drivable cannot touch one.
  std::vector<double> rest = test::lattice<2, double>(6, 4, 1, 0.005);
  std::vector<int> ids;
  for (int i = 0; i < 24; ++i) ids.push_back(i);
  std::vector<std::uint8_t> fixed(24, 0);
  fixed[0] = 1;
  for (int variant = 0; variant < 2; ++variant) {
    MsmModelConfig<2, double> mc;
    mc.particle_count = 24;
    mc.rest_positions = rest.data();
    mc.drivable_ids = ids.data();
    mc.drivable_count = variant == 0 ? 24 : 23;
    mc.fixed = variant == 0 ? fixed.data() : nullptr;
    std::vector<unsigned char> block(msm_model_workspace_size(mc));
    Arena arena(block.data(), block.size());
    MsmModel<2, double> model;
    ASSERT_EQ(msm_model_init(arena, mc, model), Status::ok);
    GraspGuardConfig config = rig_config();
    std::vector<unsigned char> guard_block(grasp_guard_workspace_size(model, config));
    Arena guard_arena(guard_block.data(), guard_block.size());
    GraspGuard<2, double> guard;
    GraspObject<2, double> object;
    object.squeeze_axis = Eigen::Vector2d(1, 0);
    EXPECT_EQ(grasp_guard_init(guard_arena, model, object, config, guard), Status::invalid_argument) << variant;
  }
  GuardedObject<2, double> object(test::lattice<2, double>(6, 4, 1, 0.005));
  GraspObject<2, double> spec;
  EXPECT_EQ(object.build_guard(rig_config(), spec), Status::invalid_argument) << "zero axis";
  spec.squeeze_axis = Eigen::Vector2d(0, 2);  // along y (normalised): fine
  EXPECT_EQ(object.build_guard(rig_config(), spec), Status::ok);
  EXPECT_NEAR(object.guard.extent_m, 0.015, 1e-12);
  const int a[] = {0, 1};
  const int b[] = {1, 23};
  spec.jaw_a_ids = a;
  spec.jaw_a_count = 2;
  spec.jaw_b_ids = b;
  spec.jaw_b_count = 2;
  EXPECT_EQ(object.build_guard(rig_config(), spec), Status::invalid_argument) << "a particle on both jaws";
  const int b2[] = {22, 99};
  spec.jaw_b_ids = b2;
  EXPECT_EQ(object.build_guard(rig_config(), spec), Status::invalid_argument) << "id out of range";
  const int b3[] = {22, 23};
  spec.jaw_b_ids = b3;
  EXPECT_EQ(object.build_guard(rig_config(), spec), Status::ok) << "explicit jaws";
  // Too small a block, and a measuring arena.
  GraspGuardConfig config = rig_config();
  std::vector<unsigned char> small(grasp_guard_workspace_size(object.model, config) / 2);
  Arena arena(small.data(), small.size());
  GraspGuard<2, double> guard;
  EXPECT_EQ(grasp_guard_init(arena, object.model, spec, config, guard), Status::capacity_exceeded);
  Arena measuring;
  EXPECT_EQ(grasp_guard_init(measuring, object.model, spec, config, guard), Status::capacity_exceeded);
  EXPECT_FALSE(guard.initialized());
  MsmModel<2, double> empty;
  EXPECT_EQ(grasp_guard_workspace_size(empty, config), 0u);
}

TEST(GraspGuardInit, NamesAreStable) {
  EXPECT_STREQ(guard_reason_name(GuardReason::predicted_strain), "predicted_strain");
  EXPECT_STREQ(guard_reason_name(GuardReason::stale_camera), "stale_camera");
  EXPECT_STREQ(grasp_verdict_name(GraspVerdict::limit), "limit");
  EXPECT_STREQ(guard_source_name(GuardSource::wrench), "wrench");
  for (int r = 0; r < kGuardReasonCount; ++r)
    EXPECT_STRNE(guard_reason_name(static_cast<GuardReason>(r)), "unknown") << r;
}

}  // namespace
}  // namespace pliant
