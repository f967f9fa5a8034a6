#include "pliant/host/replay/replay_session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "pliant/hal/clock.hpp"
#include "pliant/hal/mock/fault_script.hpp"
#include "pliant/hal/mock/replay_devices.hpp"
#include "pliant/host/replay/online_estimator.hpp"
#include "pliant/host/replay/replay_channels.hpp"

namespace pliant::host {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kFaultStep_s = 0.001;  // stepped clock advance while no device delivers

hal::FaultScript parse_script(const std::string& text) {
  hal::FaultScript script;
  hal::FaultScriptError error;
  if (hal::parse_fault_script(text.data(), text.size(), script, error) != hal::HalStatus::ok) {
    throw std::invalid_argument("fault script:" + std::to_string(error.line) + ":" + std::to_string(error.column) +
                                ": " + error.message);
  }
  for (hal::FaultDevice d : {hal::FaultDevice::color_camera, hal::FaultDevice::depth_camera}) {
    if (script.of(d).size() > 0) {
      throw std::invalid_argument(std::string("fault script: '") + hal::fault_device_name(d) +
                                  "' events cannot be replayed (a recording's media are not played back)");
    }
  }
  return script;
}

// A ManualClock stepped from 0, or the steady clock read relative to the replay's start.
class ReplayClock final : public hal::Clock {
 public:
  explicit ReplayClock(bool manual) : manual_(manual), origin_s_(steady_.now_s()) {}
  double now_s() const noexcept override { return manual_ ? manual_clock_.now_s() : steady_.now_s() - origin_s_; }
  bool manual() const { return manual_; }
  void set(double t_s) { (void)manual_clock_.set(t_s); }

 private:
  bool manual_;
  hal::SteadyClock steady_;
  hal::ManualClock manual_clock_{0.0};
  double origin_s_;
};

void configure_and_start(hal::Device& device, const char* name) {
  const hal::HalStatus configured = device.configure();
  if (configured != hal::HalStatus::ok) {
    throw std::runtime_error(std::string("replay ") + name + ": configure: " + hal::hal_status_name(configured));
  }
  const hal::HalStatus started = device.start();
  if (started != hal::HalStatus::ok) {
    throw std::runtime_error(std::string("replay ") + name + ": start: " + hal::hal_status_name(started));
  }
}

}  // namespace

const char* replay_device_name(ReplayDevice device) noexcept {
  switch (device) {
    case ReplayDevice::particles: return "particles";
    case ReplayDevice::wrench: return "wrench";
    case ReplayDevice::gripper: return "gripper";
  }
  return "unknown";
}

ReplaySummary replay_recording(const Recording& recording, const ReplayOptions& options,
                               const std::function<void(const ReplayEvent&)>& on_event,
                               const std::function<bool()>& keep_going) {
  if (!(std::isfinite(options.timing.speed) && options.timing.speed > 0)) {
    throw std::invalid_argument("replay speed must be a positive number");
  }
  if (options.candidates < 3) throw std::invalid_argument("the online estimator needs at least 3 candidates");
  if (options.alpha_candidates < 1 || options.alpha_candidates > kMaxOnlineAlphaRows) {
    throw std::invalid_argument("the online estimator takes 1 to " + std::to_string(kMaxOnlineAlphaRows) +
                                " msm_alpha rows");
  }
  if (options.step_candidates < 1 || options.step_candidates > kMaxOnlineStepRows) {
    throw std::invalid_argument("the online estimator takes 1 to " + std::to_string(kMaxOnlineStepRows) +
                                " rows of steps per frame");
  }
  if (options.equilibrium_iterations < 0 || options.equilibrium_iterations > kMaxEquilibriumIterations) {
    throw std::invalid_argument("the quasi-static row takes 0 to " + std::to_string(kMaxEquilibriumIterations) +
                                " iterations per frame");
  }
  if (!(options.msm_alpha > 0 && options.msm_alpha <= 1)) throw std::invalid_argument("msm_alpha must be in (0, 1]");
  const hal::FaultScript script = parse_script(options.fault_script);
  const ReplayChannels channels = replay_channels_of(recording);
  const bool stepped = options.timing.mode == hal::ReplayMode::stepped;
  ReplayClock clock(stepped);
  // The devices themselves always run in real time on the replay clock; "stepped" is the clock.
  const hal::ReplayTiming device_timing{hal::ReplayMode::realtime, options.timing.speed};

  hal::ReplayParticleObserver observer(channels.particles, recording.dimension, clock, device_timing);
  std::optional<hal::ReplayForceTorque> ft;
  std::optional<hal::ReplayGripper> gripper;
  if (channels.wrench) ft.emplace(*channels.wrench, clock, device_timing);
  if (channels.gripper) gripper.emplace(*channels.gripper, clock, device_timing);
  auto schedule = [](auto& device, const hal::FaultSchedule& s, const char* name) {
    if (device.set_fault_schedule(s) != hal::HalStatus::ok) {
      throw std::invalid_argument(std::string("fault script: a fault kind the ") + name + " cannot have");
    }
  };
  schedule(observer, script.of(hal::FaultDevice::observer), "particle observer");
  if (ft) schedule(*ft, script.of(hal::FaultDevice::force_torque), "force/torque sensor");
  if (gripper) schedule(*gripper, script.of(hal::FaultDevice::gripper), "gripper");
  if (!ft && script.of(hal::FaultDevice::force_torque).size() > 0) {
    throw std::invalid_argument("fault script: 'ft' events but the recording has no wrench.csv");
  }
  if (!gripper && script.of(hal::FaultDevice::gripper).size() > 0) {
    throw std::invalid_argument("fault script: 'gripper' events but the recording has no gripper.csv");
  }

  std::unique_ptr<OnlineRecordingEstimator> estimator;
  if (options.estimate) {
    OnlineDeformabilityConfig config;
    config.candidates = options.candidates;
    config.alpha_candidates = options.alpha_candidates;
    config.step_candidates = options.step_candidates;
    config.equilibrium_iterations = options.equilibrium_iterations;
    estimator = std::make_unique<OnlineRecordingEstimator>(recording, config, options.msm_alpha);
  }

  configure_and_start(observer, "particle observer");
  if (ft) configure_and_start(*ft, "force/torque sensor");
  if (gripper) configure_and_start(*gripper, "gripper");

  hal::HalStatus last_status[3] = {hal::HalStatus::ok, hal::HalStatus::ok, hal::HalStatus::ok};
  auto report = [&](ReplayDevice device, hal::HalStatus status, ReplayEvent& event) {
    const auto d = static_cast<int>(device);
    const bool failure = status != hal::HalStatus::ok && status != hal::HalStatus::no_data;
    const bool changed = failure ? status != last_status[d] : last_status[d] != hal::HalStatus::ok;
    if (status != hal::HalStatus::no_data) last_status[d] = failure ? status : hal::HalStatus::ok;
    if (status == hal::HalStatus::ok || (failure && changed)) {
      event.device = device;
      event.status = status;
      event.now_s = clock.now_s();
      if (on_event) on_event(event);
    }
  };

  ReplaySummary summary;
  OnlineDeformabilityEstimate estimate;
  double previous_stamp = std::numeric_limits<double>::quiet_NaN();
  hal::ParticleFrame frame;
  hal::WrenchReading wrench;
  hal::GripperReading grip;
  for (;;) {
    if (keep_going && !keep_going()) {
      summary.interrupted = true;
      break;
    }
    const bool all_finished = observer.finished() && (!ft || ft->finished()) && (!gripper || gripper->finished());
    if (all_finished) break;
    const double next_due =
        std::min({observer.next_due_s(), ft ? ft->next_due_s() : kInf, gripper ? gripper->next_due_s() : kInf});
    if (clock.manual()) {
      clock.set(std::max(next_due, clock.now_s()));
    } else {
      const double wait_s = std::min(next_due - clock.now_s(), 0.05);
      if (wait_s > 0) std::this_thread::sleep_for(std::chrono::duration<double>(wait_s));
    }
    bool delivered = false;
    {
      const hal::HalStatus s = observer.read(frame);
      ReplayEvent event;
      if (s == hal::HalStatus::ok) {
        delivered = true;
        event.particles = &frame;
        if (estimator) {
          const double dt = (frame.header.stamp_s - previous_stamp) * options.timing.speed;
          const double recorded_t = recording.frame_times_s[static_cast<std::size_t>(observer.last_index())];
          // The first frame only anchors dt (the estimator starts at the rest shape).
          if (std::isfinite(previous_stamp)) {
            event.estimator_status = estimator->update(frame.positions, recorded_t, dt);
            estimate = estimator->estimate();
            event.estimate = &estimate;
          }
          previous_stamp = frame.header.stamp_s;
        }
      }
      report(ReplayDevice::particles, s, event);
    }
    if (ft) {
      const hal::HalStatus s = ft->read(wrench);
      ReplayEvent event;
      event.wrench = &wrench;
      delivered = delivered || s == hal::HalStatus::ok;
      report(ReplayDevice::wrench, s, event);
    }
    if (gripper) {
      const hal::HalStatus s = gripper->read(grip);
      ReplayEvent event;
      event.gripper = &grip;
      delivered = delivered || s == hal::HalStatus::ok;
      report(ReplayDevice::gripper, s, event);
    }
    // A read fault holds every due sample back: move the stepped clock on so they expire.
    if (!delivered && clock.manual()) clock.set(clock.now_s() + kFaultStep_s);
    if (!delivered && !clock.manual()) std::this_thread::sleep_for(std::chrono::duration<double>(kFaultStep_s));
  }

  summary.duration_s = clock.now_s();
  summary.skipped_rows = channels.skipped_rows;
  auto fill = [&](ReplayDevice d, const hal::Device& device, const hal::FaultCounters& injected) {
    ReplayDeviceSummary& s = summary.devices[static_cast<int>(d)];
    s.present = true;
    s.counters = device.counters();
    s.injected = injected;
  };
  fill(ReplayDevice::particles, observer, observer.fault_counters());
  if (ft) fill(ReplayDevice::wrench, *ft, ft->fault_counters());
  if (gripper) fill(ReplayDevice::gripper, *gripper, gripper->fault_counters());
  if (estimator) {
    summary.estimated = true;
    summary.estimate = estimator->estimate();
    summary.estimator_rejected_frames = estimator->rejected_frames();
    summary.estimator_empty_frames = estimator->empty_frames();
  }
  return summary;
}

}  // namespace pliant::host
