// Decoded telemetry messages as JSON lines (docs/telemetry.md, "pliant telemetry"): one object
// per message with "type", "seq", "stamp_us" and the message's fields by name. Reals are the
// shortest decimal that reads back to the same f32/f64; NaN and infinities are null. Codes are
// names: verdict and reason as the core's grasp_verdict_name / guard_reason_name,
// fault_sources as guard_source_name, particle status as "observed" / "predicted" / "lost",
// counters by pliant_tm_counter_name (unknown ids by their number).
#pragma once

#include <string>

#include "pliant_telemetry.h"

namespace pliant::host::telemetry {

/// The JSON object for one decoded message, without a line break. Throws std::invalid_argument
/// for a message type the codec does not deliver.
std::string message_json(const pliant_tm_message_t& message);

}  // namespace pliant::host::telemetry
