// `pliant record`: the capture loop over the opened devices.
//
// Starts every device, then polls each one in turn with its non-blocking HAL read (one read per
// device per pass) and hands what arrived to the RecordWriter, sleeping idle_sleep_s when a pass
// brought nothing. Stops when the first of these happens:
//   duration       duration_s > 0 and the clock has passed t0 + duration_s (t0: the writer's)
//   interrupted    SIGINT or SIGTERM (Ctrl-C) arrived; a second one ends the process at once
//   sources_ended  there is at least one file-backed source and every one has ended
// and then stops every device. Transport faults of a device (timeouts, disconnects) do not stop
// the capture: the drivers reconnect by themselves and the HAL counts them. A media error
// (record_media.hpp) throws std::runtime_error; an exception from on_first_color (the region
// check) is passed on.
// Host code. Thread safety: one thread; installs process-wide signal handlers while it runs
// (restored on return).
#pragma once

#include <functional>
#include <vector>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"
#include "record_devices.hpp"
#include "record_writer.hpp"

namespace pliant::cli {

enum class StopReason { duration, interrupted, sources_ended };

/// "duration", "interrupted", "sources_ended".
const char* stop_reason_name(StopReason reason) noexcept;

struct CaptureOptions {
  double duration_s = 0;        ///< 0: no limit
  double idle_sleep_s = 0.001;  ///< sleep after a pass that brought nothing
  /// Called with the first colour frame the writer kept (may throw to abort).
  std::function<void(const hal::ColorFrame&)> on_first_color;
};

/// Catches SIGINT and SIGTERM while alive (see the top); interrupted() says whether one came.
class InterruptCatcher {
 public:
  InterruptCatcher();
  ~InterruptCatcher();  ///< release()
  /// Restores the previous handlers (idempotent): from then on the signals act as before.
  void release() noexcept;
  InterruptCatcher(const InterruptCatcher&) = delete;
  InterruptCatcher& operator=(const InterruptCatcher&) = delete;
  static bool interrupted() noexcept;

 private:
  bool active_ = true;
};

/// Runs the capture (see the top). `devices` are configured, not started.
StopReason run_capture(const std::vector<RecordDevice*>& devices, RecordWriter& writer, const hal::Clock& clock,
                       const CaptureOptions& options);

}  // namespace pliant::cli
