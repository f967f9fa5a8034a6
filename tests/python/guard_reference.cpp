// guard_reference: a scripted grasp through the core grasp guard, printed as JSON for
// test_guard.py, which feeds the same samples to pliant.GraspGuard and compares every output.
//
// The object: a 3D ball of 123 particles at 10 mm (radius 3 cells), squeezed along x. The grasp:
// 1 kHz cycles; the gripper closes from 70 mm at 10 mm/s with a Hertz-like force past a 64 mm
// contact, one NaN force sample and a bus-off wrench burst on the way; the camera's strain every
// 33 cycles from grasp_guard_measure_strain on the ball compressed as far as the jaws are;
// the estimate settles at msm_beta 0.5 +- 0.03 after 0.2 s; the guard is reset at 0.7 s. Prints
// {"rest", "axis", "config", "cycles": [{"now", "gripper", "wrench", "deformation" with
// "closure_for_strain", "estimate", "reset", "output"}]}; NaN is printed as null.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <vector>

#include <nlohmann/json.hpp>

#include "pliant/core/arena.hpp"
#include "pliant/core/grasp_guard.hpp"

namespace {

using pliant::GraspGuardConfig;
using Vec = Eigen::Vector3d;
constexpr double kSpacing = 0.01;
constexpr double kContact = 0.064;

std::vector<double> ball() {
  std::vector<double> rest;
  for (int z = -3; z <= 3; ++z) {
    for (int y = -3; y <= 3; ++y) {
      for (int x = -3; x <= 3; ++x) {
        if (x * x + y * y + z * z > 9) continue;
        for (int c : {x, y, z}) rest.push_back(kSpacing * c);
      }
    }
  }
  return rest;
}

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json output_json(const pliant::GraspGuardOutput& o) {
  nlohmann::json reasons = nlohmann::json::array();
  for (int r = 1; r < pliant::kGuardReasonCount; ++r) {
    if ((o.reasons & (1u << r)) != 0) reasons.push_back(pliant::guard_reason_name(static_cast<pliant::GuardReason>(r)));
  }
  return {{"verdict", pliant::grasp_verdict_name(o.verdict)},
          {"reason", pliant::guard_reason_name(o.reason)},
          {"stop_action", o.stop_action == pliant::StopAction::open ? "open" : "freeze"},
          {"reasons", reasons},
          {"in_contact", o.in_contact},
          {"slip", o.slip},
          {"closure_m", number(o.closure_m)},
          {"force_n", number(o.force_n)},
          {"strain", number(o.strain)},
          {"allowed_force_n", number(o.allowed_force_n)},
          {"beta_low", number(o.beta_low)},
          {"beta_high", number(o.beta_high)},
          {"predicted_strain", number(o.predicted_strain)},
          {"safe_closure_m", number(o.safe_closure_m)},
          {"safe_width_m", number(o.safe_width_m)},
          {"predicted_force_n", number(o.predicted_force_n)},
          {"stiffness_n_per_m", number(o.stiffness_n_per_m)}};
}

// The ball squeezed by `closure` along x: uniform compression, the other axes bulging.
std::vector<Vec> squeezed(const std::vector<double>& rest, double closure) {
  const double stretch = 1.0 - closure / kContact;
  const double bulge = 1.0 / std::sqrt(stretch);
  std::vector<Vec> out;
  for (std::size_t i = 0; i < rest.size(); i += 3)
    out.emplace_back(rest[i] * stretch, rest[i + 1] * bulge, rest[i + 2] * bulge);
  return out;
}

}  // namespace

int main() {
  const std::vector<double> rest = ball();
  const int n = static_cast<int>(rest.size() / 3);
  std::vector<int> all(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) all[static_cast<std::size_t>(i)] = i;
  pliant::MsmModelConfig<3, double> model_config;
  model_config.particle_count = n;
  model_config.rest_positions = rest.data();
  model_config.drivable_ids = all.data();
  model_config.drivable_count = n;
  std::vector<unsigned char> model_block(pliant::msm_model_workspace_size(model_config));
  pliant::Arena model_arena(model_block.data(), model_block.size());
  pliant::MsmModel<3, double> model;
  if (pliant::msm_model_init(model_arena, model_config, model) != pliant::Status::ok) return 1;

  GraspGuardConfig config;
  config.max_force_n = 12;
  config.nominal_force_n = 8;
  config.max_strain = 0.12;
  pliant::GraspObject<3, double> object;
  object.squeeze_axis = Vec::UnitX();
  std::vector<unsigned char> guard_block(pliant::grasp_guard_workspace_size(model, config), 0);
  pliant::Arena guard_arena(guard_block.data(), guard_block.size());
  pliant::GraspGuard<3, double> guard;
  if (pliant::grasp_guard_init(guard_arena, model, object, config, guard) != pliant::Status::ok) return 1;

  nlohmann::json cycles = nlohmann::json::array();
  pliant::GraspGuardInput input;
  for (int k = 0; k < 900; ++k) {
    const double now = 1.0 + 0.001 * k;
    const double width = 0.070 - 0.010 * 0.001 * k;
    const double closure = std::max(0.0, kContact - width);
    nlohmann::json cycle = {{"now", now}};
    input.now_s = now;
    input.gripper = {};
    input.gripper.stamp_s = now;
    input.gripper.width_m = width;
    input.gripper.force_n = k == 500 ? std::nan("") : 2e4 * std::pow(closure, 1.5) + 0.01;
    input.gripper.valid = true;
    cycle["gripper"] = {{"stamp", now}, {"width", width}, {"force", number(input.gripper.force_n)}, {"valid", true}};
    input.wrench = {};
    input.wrench.stamp_s = now;
    for (int a = 0; a < 6; ++a) input.wrench.wrench[a] = a == 2 ? 1.0 + 0.2 * std::sin(0.3 * k) : 0.0;
    input.wrench.valid = true;
    input.wrench.bus_off = k >= 600 && k < 605;
    cycle["wrench"] = {{"stamp", now},
                       {"wrench", std::vector<double>(input.wrench.wrench, input.wrench.wrench + 6)},
                       {"valid", true},
                       {"bus_off", input.wrench.bus_off}};
    if (k % 33 == 0) {
      const std::vector<Vec> frame = squeezed(rest, closure);
      pliant::GraspStrainMeasurement m;
      (void)pliant::grasp_guard_measure_strain(model, guard, frame.data(), m);
      input.deformation = {};
      input.deformation.stamp_s = now;
      input.deformation.strain = m.strain;
      input.deformation.valid = true;
      cycle["deformation"] = {{"stamp", now}, {"strain", number(m.strain)}, {"valid", true}};
      cycle["closure_for_strain"] = closure;
    }
    if (k >= 200 && k % 10 == 0) {
      input.estimate = {};
      input.estimate.stamp_s = now;
      input.estimate.msm_beta = 0.5;
      input.estimate.msm_beta_std = 0.03;
      input.estimate.valid = true;
      cycle["estimate"] = {{"stamp", now}, {"msm_beta", 0.5}, {"msm_beta_std", 0.03}, {"valid", true}};
    }
    if (k == 700) {  // a new grasp: the guard forgets the contact and the force fit
      pliant::grasp_guard_reset(guard);
      cycle["reset"] = true;
    }
    pliant::GraspGuardOutput output;
    (void)pliant::grasp_guard_update(guard, input, output);
    cycle["output"] = output_json(output);
    cycles.push_back(cycle);
  }
  const nlohmann::json document = {{"rest", rest},
                                   {"axis", {1.0, 0.0, 0.0}},
                                   {"config", {{"max_force_n", 12.0}, {"nominal_force_n", 8.0}, {"max_strain", 0.12}}},
                                   {"cycles", cycles}};
  std::cout << document.dump() << '\n';
  return std::cout ? 0 : 1;
}
