#include "record_capture.hpp"

#include <signal.h>

#include <chrono>
#include <csignal>
#include <stdexcept>
#include <thread>

namespace pliant::cli {
namespace {

volatile std::sig_atomic_t g_interrupted = 0;

extern "C" void on_interrupt(int signal_number) {
  if (g_interrupted != 0) {
    // The second one: give the user the default action (end the process) at once.
    ::signal(signal_number, SIG_DFL);
    ::raise(signal_number);
    return;
  }
  g_interrupted = 1;
}

struct sigaction g_previous_int;
struct sigaction g_previous_term;

// Stops the started devices however the loop ends.
class StopOnExit {
 public:
  explicit StopOnExit(const std::vector<RecordDevice*>& devices) : devices_(devices) {}
  ~StopOnExit() {
    for (RecordDevice* d : devices_) {
      if (d->device().state() == hal::LifecycleState::active) (void)d->device().stop();
    }
  }
  StopOnExit(const StopOnExit&) = delete;
  StopOnExit& operator=(const StopOnExit&) = delete;

 private:
  const std::vector<RecordDevice*>& devices_;
};

// One read of `d`; true when it delivered something the writer kept.
bool poll(RecordDevice& d, RecordWriter& writer, const CaptureOptions& options, bool& first_color) {
  if (hal::ColorCamera* camera = d.color()) {
    hal::ColorFrame frame;
    if (camera->read(frame) != hal::HalStatus::ok) return false;
    if (!writer.add_color(frame)) return true;
    if (first_color) {
      first_color = false;
      if (options.on_first_color) options.on_first_color(frame);
    }
    return true;
  }
  if (hal::DepthCamera* camera = d.depth()) {
    hal::DepthFrame frame;
    if (camera->read(frame) != hal::HalStatus::ok) return false;
    writer.add_depth(frame);
    return true;
  }
  if (hal::ForceTorqueSensor* ft = d.ft()) {
    hal::WrenchReading reading;
    if (ft->read(reading) != hal::HalStatus::ok) return false;
    writer.add_wrench(reading);
    return true;
  }
  if (hal::Gripper* gripper = d.gripper()) {
    hal::GripperReading reading;
    if (gripper->read(reading) != hal::HalStatus::ok) return false;
    writer.add_gripper(reading);
    return true;
  }
  return false;
}

}  // namespace

const char* stop_reason_name(StopReason reason) noexcept {
  switch (reason) {
    case StopReason::duration: return "duration";
    case StopReason::interrupted: return "interrupted";
    case StopReason::sources_ended: return "sources_ended";
  }
  return "?";
}

InterruptCatcher::InterruptCatcher() {
  g_interrupted = 0;
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;
  sigaction(SIGINT, &action, &g_previous_int);
  sigaction(SIGTERM, &action, &g_previous_term);
}

InterruptCatcher::~InterruptCatcher() { release(); }

void InterruptCatcher::release() noexcept {
  if (!active_) return;
  active_ = false;
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
}

bool InterruptCatcher::interrupted() noexcept { return g_interrupted != 0; }

StopReason run_capture(const std::vector<RecordDevice*>& devices, RecordWriter& writer, const hal::Clock& clock,
                       const CaptureOptions& options) {
  StopOnExit stopper(devices);
  for (RecordDevice* d : devices) d->start();
  bool any_file = false;
  for (RecordDevice* d : devices) any_file = any_file || is_file_backed(d->spec().kind);
  bool first_color = true;
  const auto idle = std::chrono::duration<double>(options.idle_sleep_s);
  for (;;) {
    if (g_interrupted != 0) return StopReason::interrupted;
    if (options.duration_s > 0 && clock.now_s() - writer.t0_s() >= options.duration_s) return StopReason::duration;
    bool got = false;
    for (RecordDevice* d : devices) got = poll(*d, writer, options, first_color) || got;
    const std::string media_error = writer.media_error();
    if (!media_error.empty()) throw std::runtime_error("writing the media: " + media_error);
    if (any_file) {
      bool all_ended = true;
      for (RecordDevice* d : devices) all_ended = all_ended && (!is_file_backed(d->spec().kind) || d->ended());
      if (all_ended) return StopReason::sources_ended;
    }
    if (!got) std::this_thread::sleep_for(idle);
  }
}

}  // namespace pliant::cli
