#include "guard_values.hpp"

#include <cstdint>
#include <string>

#include <pybind11/numpy.h>

#include "convert.hpp"

namespace pliant::python {
namespace {

using Config = GraspGuardConfig;

struct DoubleField {
  const char* name;
  double Config::*member;
};
const DoubleField kDoubleFields[] = {
    {"max_strain", &Config::max_strain},
    {"max_indentation_m", &Config::max_indentation_m},
    {"max_force_n", &Config::max_force_n},
    {"nominal_force_n", &Config::nominal_force_n},
    {"contact_width_m", &Config::contact_width_m},
    {"contact_force_n", &Config::contact_force_n},
    {"contact_width_tolerance", &Config::contact_width_tolerance},
    {"max_width_m", &Config::max_width_m},
    {"current_gain_n_per_a", &Config::current_gain_n_per_a},
    {"current_offset_a", &Config::current_offset_a},
    {"gripper_timeout_s", &Config::gripper_timeout_s},
    {"wrench_timeout_s", &Config::wrench_timeout_s},
    {"camera_timeout_s", &Config::camera_timeout_s},
    {"estimate_timeout_s", &Config::estimate_timeout_s},
    {"cycle_timeout_s", &Config::cycle_timeout_s},
    {"clock_tolerance_s", &Config::clock_tolerance_s},
    {"hysteresis_margin", &Config::hysteresis_margin},
    {"stop_overshoot", &Config::stop_overshoot},
    {"confidence_k", &Config::confidence_k},
    {"max_beta_std", &Config::max_beta_std},
    {"slip_cutoff_hz", &Config::slip_cutoff_hz},
    {"slip_ratio", &Config::slip_ratio},
    {"slip_floor_n", &Config::slip_floor_n},
    {"slip_ceiling_n", &Config::slip_ceiling_n},
    {"slip_force_rate_per_s", &Config::slip_force_rate_per_s},
    {"force_fit_spacing_m", &Config::force_fit_spacing_m},
    {"force_fit_forgetting", &Config::force_fit_forgetting},
    {"force_model_min_closure_m", &Config::force_model_min_closure_m},
    {"prediction_max_closure_m", &Config::prediction_max_closure_m},
    {"relax_tolerance", &Config::relax_tolerance},
};

struct IntField {
  const char* name;
  int Config::*member;
};
const IntField kIntFields[] = {
    {"wrench_frozen_samples", &Config::wrench_frozen_samples},
    {"clear_samples", &Config::clear_samples},
    {"prediction_beta_points", &Config::prediction_beta_points},
    {"prediction_closure_points", &Config::prediction_closure_points},
    {"prediction_refine_steps", &Config::prediction_refine_steps},
    {"relax_max_iterations", &Config::relax_max_iterations},
};

struct MaskField {
  const char* name;
  std::uint32_t Config::*member;
};
const MaskField kMaskFields[] = {
    {"gripper_fault_mask", &Config::gripper_fault_mask},
    {"wrench_fault_mask", &Config::wrench_fault_mask},
    {"camera_fault_mask", &Config::camera_fault_mask},
};

double real(py::handle value, const std::string& what) {
  if (py::isinstance<py::bool_>(value) || !(py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value))) {
    throw py::type_error(what + " must be a number");
  }
  return value.cast<double>();
}

long long whole(py::handle value, const std::string& what) {
  if (py::isinstance<py::bool_>(value) || !py::isinstance<py::int_>(value))
    throw py::type_error(what + " must be an int");
  return value.cast<long long>();
}

GraspVerdict verdict_of(py::handle value, const std::string& what) {
  const std::string name = value.cast<std::string>();
  for (GraspVerdict v : {GraspVerdict::ok, GraspVerdict::limit, GraspVerdict::stop}) {
    if (name == grasp_verdict_name(v)) return v;
  }
  throw py::value_error(what + " must be 'ok', 'limit' or 'stop', not '" + name + "'");
}

StopAction action_of(py::handle value, const std::string& what) {
  const std::string name = value.cast<std::string>();
  if (name == "open") return StopAction::open;
  if (name == "freeze") return StopAction::freeze;
  throw py::value_error(what + " must be 'open' or 'freeze', not '" + name + "'");
}

bool set_named_field(Config& config, const std::string& key, py::handle value) {
  for (const DoubleField& f : kDoubleFields) {
    if (key != f.name) continue;
    config.*f.member = real(value, key);
    return true;
  }
  for (const IntField& f : kIntFields) {
    if (key != f.name) continue;
    const long long v = whole(value, key);
    if (v < -(1LL << 31) || v >= (1LL << 31)) throw py::value_error(key + " is out of range");
    config.*f.member = static_cast<int>(v);
    return true;
  }
  for (const MaskField& f : kMaskFields) {
    if (key != f.name) continue;
    const long long v = whole(value, key);
    if (v < 0 || v > 0xffffffffLL) throw py::value_error(key + " must be a 32-bit mask");
    config.*f.member = static_cast<std::uint32_t>(v);
    return true;
  }
  return false;
}

void set_fault_verdicts(Config& config, py::handle value) {
  if (!py::isinstance<py::dict>(value)) throw py::type_error("fault_verdict must be a dict {source: verdict}");
  for (const auto& item : value.cast<py::dict>()) {
    const std::string source = item.first.cast<std::string>();
    bool known = false;
    for (int s = 0; s < kGuardSourceCount; ++s) {
      if (source != guard_source_name(static_cast<GuardSource>(s))) continue;
      config.fault_verdict[s] = verdict_of(item.second, "fault_verdict['" + source + "']");
      known = true;
    }
    if (!known) throw py::value_error("fault_verdict: unknown source '" + source + "'");
  }
}

void set_field(Config& config, const std::string& key, py::handle value) {
  if (set_named_field(config, key, value)) return;
  if (key == "latch_stop") {
    if (!py::isinstance<py::bool_>(value)) throw py::type_error("latch_stop must be a bool");
    config.latch_stop = value.cast<bool>();
  } else if (key == "force_source") {
    const std::string name = value.cast<std::string>();
    if (name != "force_sensor" && name != "motor_current") {
      throw py::value_error("force_source must be 'force_sensor' or 'motor_current', not '" + name + "'");
    }
    config.force_source = name == "force_sensor" ? ForceSource::force_sensor : ForceSource::motor_current;
  } else if (key == "uncertain_estimate_verdict") {
    config.uncertain_estimate_verdict = verdict_of(value, key);
  } else if (key == "exceeded_stop_action") {
    config.exceeded_stop_action = action_of(value, key);
  } else if (key == "fault_stop_action") {
    config.fault_stop_action = action_of(value, key);
  } else if (key == "fault_verdict") {
    set_fault_verdicts(config, value);
  } else {
    throw py::value_error("GraspGuard: unknown option '" + key + "' (the fields of GraspGuardConfig)");
  }
}

// The keys a sample dict may hold, checked so that a misspelt key is an error, not ignored.
void check_keys(const py::dict& d, const char* what, std::initializer_list<const char*> keys) {
  for (const auto& item : d) {
    const std::string key = item.first.cast<std::string>();
    bool known = false;
    for (const char* k : keys) known = known || key == k;
    if (!known) throw py::value_error(std::string(what) + ": unknown key '" + key + "'");
  }
}

py::dict dict_of(py::handle value, const char* what) {
  if (!py::isinstance<py::dict>(value)) throw py::type_error(std::string(what) + " must be a dict");
  return value.cast<py::dict>();
}

// stamp, status, valid, bus_off, timeout: the fields every device sample has.
template <typename Sample>
void read_common(const py::dict& d, const std::string& what, Sample& s) {
  if (d.contains("stamp")) s.stamp_s = real(d["stamp"], what + "['stamp']");
  if (d.contains("status")) {
    const long long bits = whole(d["status"], what + "['status']");
    if (bits < 0 || bits > 0xffffffffLL) throw py::value_error(what + "['status'] must be a 32-bit word");
    s.status_bits = static_cast<std::uint32_t>(bits);
  }
  s.valid = d.contains("valid") ? d["valid"].cast<bool>() : true;
  s.bus_off = d.contains("bus_off") && d["bus_off"].cast<bool>();
  s.timeout = d.contains("timeout") && d["timeout"].cast<bool>();
}

}  // namespace

GraspGuardConfig guard_config(const py::dict& options) {
  GraspGuardConfig config;
  for (const auto& item : options) set_field(config, item.first.cast<std::string>(), item.second);
  return config;
}

void read_sample(py::handle value, GripperSample& s) {
  const py::dict d = dict_of(value, "gripper");
  check_keys(d, "gripper", {"stamp", "width", "force", "current", "status", "valid", "bus_off", "timeout"});
  read_common(d, "gripper", s);
  if (d.contains("width")) s.width_m = real(d["width"], "gripper['width']");
  if (d.contains("force")) s.force_n = real(d["force"], "gripper['force']");
  if (d.contains("current")) s.current_a = real(d["current"], "gripper['current']");
}

void read_sample(py::handle value, WrenchSample& s) {
  const py::dict d = dict_of(value, "wrench");
  check_keys(d, "wrench", {"stamp", "wrench", "status", "valid", "bus_off", "timeout"});
  read_common(d, "wrench", s);
  if (d.contains("wrench")) {
    const py::array_t<double> w = real_array(d["wrench"], "wrench['wrench']", {6}, "(6,): Fx Fy Fz N, Tx Ty Tz N m");
    for (py::ssize_t k = 0; k < 6; ++k) s.wrench[k] = w.at(k);
  }
}

void read_sample(py::handle value, DeformationSample& s) {
  const py::dict d = dict_of(value, "deformation");
  check_keys(d, "deformation", {"stamp", "strain", "status", "valid", "bus_off", "timeout"});
  read_common(d, "deformation", s);
  if (d.contains("strain")) s.strain = real(d["strain"], "deformation['strain']");
}

void read_sample(py::handle value, EstimateSample& s) {
  const py::dict d = dict_of(value, "estimate");
  check_keys(d, "estimate", {"stamp", "msm_beta", "msm_beta_std", "valid"});
  if (d.contains("stamp")) s.stamp_s = real(d["stamp"], "estimate['stamp']");
  if (d.contains("msm_beta")) s.msm_beta = real(d["msm_beta"], "estimate['msm_beta']");
  if (d.contains("msm_beta_std")) s.msm_beta_std = real(d["msm_beta_std"], "estimate['msm_beta_std']");
  s.valid = d.contains("valid") ? d["valid"].cast<bool>() : true;
}

py::dict output_dict(const GraspGuardOutput& o) {
  py::list reasons;
  for (int r = 1; r < kGuardReasonCount; ++r) {
    if ((o.reasons & (1u << r)) != 0) reasons.append(guard_reason_name(static_cast<GuardReason>(r)));
  }
  py::list fault_sources;
  for (int s = 0; s < kGuardSourceCount; ++s) {
    if ((static_cast<unsigned>(o.fault_sources) & (1u << s)) != 0)
      fault_sources.append(guard_source_name(static_cast<GuardSource>(s)));
  }
  py::dict out;
  out["verdict"] = grasp_verdict_name(o.verdict);
  out["reason"] = guard_reason_name(o.reason);
  out["stop_action"] = o.stop_action == StopAction::open ? "open" : "freeze";
  out["reasons"] = reasons;
  out["fault_sources"] = fault_sources;
  out["in_contact"] = o.in_contact;
  out["slip"] = o.slip;
  out["contact_width_m"] = o.contact_width_m;
  out["closure_m"] = o.closure_m;
  out["force_n"] = o.force_n;
  out["strain"] = o.strain;
  out["allowed_force_n"] = o.allowed_force_n;
  out["beta_low"] = o.beta_low;
  out["beta_high"] = o.beta_high;
  out["predicted_strain"] = o.predicted_strain;
  out["strain_safe_closure_m"] = o.strain_safe_closure_m;
  out["force_safe_closure_m"] = o.force_safe_closure_m;
  out["safe_closure_m"] = o.safe_closure_m;
  out["safe_width_m"] = o.safe_width_m;
  out["predicted_force_n"] = o.predicted_force_n;
  out["stiffness_n_per_m"] = o.stiffness_n_per_m;
  out["slip_force_n"] = o.slip_force_n;
  return out;
}

}  // namespace pliant::python
