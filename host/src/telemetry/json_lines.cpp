// JSON text by hand: the objects are flat and small, and reals need the f32 shortest form
// (0.1f as 0.1, not the 0.10000000149011612 of its double widening).
#include "pliant/host/telemetry/json_lines.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "pliant/core/grasp_guard.hpp"

namespace pliant::host::telemetry {
namespace {

template <typename Real>
std::string real(Real value) {
  if (!std::isfinite(value)) return "null";
  char buffer[40];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

std::string quoted(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string boolean(bool value) { return value ? "true" : "false"; }

class Object {
 public:
  Object& add(std::string_view key, const std::string& json) {
    text_ += first_ ? "" : ",";
    first_ = false;
    text_ += quoted(key) + ":" + json;
    return *this;
  }
  std::string close() { return text_ + "}"; }

 private:
  std::string text_ = "{";
  bool first_ = true;
};

const char* status_name(std::uint8_t status) {
  switch (status) {
    case PLIANT_TM_OBSERVED: return "observed";
    case PLIANT_TM_PREDICTED: return "predicted";
    case PLIANT_TM_LOST: return "lost";
    default: return "unknown";  // the decoder rejects these as out of range
  }
}

// Names of the set bits of `bits`, in bit order.
template <typename Name>
std::string bit_names(std::uint32_t bits, int count, Name name) {
  std::string out = "[";
  for (int bit = 0; bit < count; ++bit) {
    if ((bits >> bit & 1u) == 0) continue;
    out += (out.size() > 1 ? "," : "") + quoted(name(bit));
  }
  return out + "]";
}

void estimate_fields(Object& o, const pliant_tm_estimate_t& e) {
  o.add("msm_beta", real(e.msm_beta))
      .add("msm_beta_std", real(e.msm_beta_std))
      .add("rms", real(e.rms))
      .add("frames", std::to_string(e.frames))
      .add("unique_minimum", boolean((e.flags & PLIANT_TM_ESTIMATE_UNIQUE_MINIMUM) != 0))
      .add("valid", boolean((e.flags & PLIANT_TM_ESTIMATE_VALID) != 0));
}

void verdict_fields(Object& o, const pliant_tm_verdict_t& v) {
  const auto reason_name = [](int reason) { return guard_reason_name(static_cast<GuardReason>(reason)); };
  const auto source_name = [](int source) { return guard_source_name(static_cast<GuardSource>(source)); };
  o.add("verdict", quoted(grasp_verdict_name(static_cast<GraspVerdict>(v.verdict))))
      .add("reason", quoted(reason_name(v.reason)))
      .add("stop_action", quoted(v.stop_action == 1 ? "open" : "freeze"))
      .add("fault_sources", bit_names(v.fault_sources, PLIANT_TM_SOURCE_COUNT, source_name))
      .add("reasons", bit_names(v.reasons, PLIANT_TM_REASON_COUNT, reason_name))
      .add("in_contact", boolean((v.flags & PLIANT_TM_VERDICT_IN_CONTACT) != 0))
      .add("slip", boolean((v.flags & PLIANT_TM_VERDICT_SLIP) != 0))
      .add("closure_m", real(v.closure_m))
      .add("force_n", real(v.force_n))
      .add("strain", real(v.strain))
      .add("allowed_force_n", real(v.allowed_force_n))
      .add("predicted_strain", real(v.predicted_strain))
      .add("safe_closure_m", real(v.safe_closure_m))
      .add("safe_width_m", real(v.safe_width_m))
      .add("predicted_force_n", real(v.predicted_force_n))
      .add("beta_low", real(v.beta_low))
      .add("beta_high", real(v.beta_high));
}

void particles_fields(Object& o, const pliant_tm_particles_t& p) {
  std::string positions = "[";
  std::string status = "[";
  for (std::uint16_t i = 0; i < p.count; ++i) {
    float xyz[3];
    std::uint8_t s = 0;
    pliant_tm_particles_get(&p, i, xyz, &s);
    positions += i == 0 ? "[" : ",[";
    for (std::uint8_t axis = 0; axis < p.dim; ++axis) positions += (axis == 0 ? "" : ",") + real(xyz[axis]);
    positions += "]";
    status += (i == 0 ? "" : ",") + quoted(status_name(s));
  }
  o.add("frame", std::to_string(p.frame))
      .add("dim", std::to_string(p.dim))
      .add("total", std::to_string(p.total))
      .add("first", std::to_string(p.first))
      .add("count", std::to_string(p.count))
      .add("positions", positions + "]")
      .add("status", status + "]");
}

void counters_fields(Object& o, const pliant_tm_counters_t& c) {
  Object values;
  for (std::uint16_t i = 0; i < c.count; ++i) {
    const pliant_tm_counter_t counter = pliant_tm_counters_get(&c, i);
    const char* name = pliant_tm_counter_name(counter.id);
    values.add(name != nullptr ? name : std::to_string(counter.id), std::to_string(counter.value));
  }
  o.add("counters", values.close());
}

}  // namespace

std::string message_json(const pliant_tm_message_t& message) {
  Object o;
  const pliant_tm_header_t& h = message.header;
  const auto head = [&](const char* type) {
    o.add("type", quoted(type)).add("seq", std::to_string(h.seq)).add("stamp_us", std::to_string(h.stamp_us));
  };
  switch (h.type) {
    case PLIANT_TM_TYPE_ESTIMATE:
      head("estimate");
      estimate_fields(o, message.body.estimate);
      break;
    case PLIANT_TM_TYPE_VERDICT:
      head("verdict");
      verdict_fields(o, message.body.verdict);
      break;
    case PLIANT_TM_TYPE_PARTICLES:
      head("particles");
      particles_fields(o, message.body.particles);
      break;
    case PLIANT_TM_TYPE_COUNTERS:
      head("counters");
      counters_fields(o, message.body.counters);
      break;
    default: throw std::invalid_argument("telemetry message of unknown type " + std::to_string(h.type));
  }
  return o.close();
}

}  // namespace pliant::host::telemetry
