// What a wire HIL grasp did, cycle by cycle, judged against the plant's true strain: contact, the
// first not-ok verdict in contact, the first cycle the guard stopped the squeeze (a verdict or
// its safe width), the true strain then, the peak true strain, the last verdict. record() after
// every rig step. Allocation-free.
#pragma once

#include <algorithm>
#include <limits>

#include "hil_supervisor.hpp"
#include "pliant/hal/mock/simulated_grasp.hpp"

namespace pliant::hil {

struct GraspLog {
  long cycles = 0;
  long contact = -1;       ///< first cycle the guard reported contact
  long first_not_ok = -1;  ///< first cycle in contact with limit or stop
  double strain_at_first = std::numeric_limits<double>::quiet_NaN();
  GuardReason first_reason = GuardReason::none;
  /// First cycle in contact that the guard stopped the squeeze: a not-ok verdict, or the
  /// fingers held at the guard's safe width (WireRig::held_at_safe_width).
  long first_stop = -1;
  double strain_at_stop = std::numeric_limits<double>::quiet_NaN();
  bool stopped_by_verdict = false;
  double peak = 0;  ///< largest true strain so far
  GraspVerdict final_verdict = GraspVerdict::ok;
  GuardReason final_reason = GuardReason::none;
  bool failed = false;  ///< the supervisor could not build its model

  /// `held`: the fingers stand at the guard's safe width this cycle.
  void record(const CycleReport& r, const hal::SimulatedGrasp& plant, bool held) noexcept {
    const long c = cycles++;
    failed = failed || r.phase == Phase::failed;
    peak = std::max(peak, plant.true_max_strain());
    if (!r.guarded) return;
    if (contact < 0 && r.out.in_contact) contact = c;
    if (first_not_ok < 0 && r.out.in_contact && r.out.verdict != GraspVerdict::ok) {
      first_not_ok = c;
      strain_at_first = plant.true_max_strain();
      first_reason = r.out.reason;
    }
    const bool not_ok = r.out.in_contact && r.out.verdict != GraspVerdict::ok;
    if (first_stop < 0 && (not_ok || held)) {
      first_stop = c;
      strain_at_stop = plant.true_max_strain();
      stopped_by_verdict = not_ok;
    }
    final_verdict = r.out.verdict;
    final_reason = r.out.reason;
  }
  /// Cycles since the guard first stopped the squeeze (-1 before it).
  long since_stop() const noexcept { return first_stop < 0 ? -1 : cycles - 1 - first_stop; }
};

}  // namespace pliant::hil
