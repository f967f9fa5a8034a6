#include "command_replay.hpp"

#include <cmath>
#include <csignal>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "atomic_write.hpp"
#include "exit_status.hpp"
#include "pliant/host/recording.hpp"
#include "pliant/host/replay/replay_session.hpp"

namespace pliant::cli {
namespace {

volatile std::sig_atomic_t g_replay_stop = 0;
extern "C" void request_replay_stop(int /*signal*/) { g_replay_stop = 1; }

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json event_json(const host::ReplayEvent& e) {
  nlohmann::json j;
  j["device"] = host::replay_device_name(e.device);
  j["now"] = e.now_s;
  if (e.status != hal::HalStatus::ok) {
    j["error"] = hal::hal_status_name(e.status);
    return j;
  }
  const hal::SampleHeader* header = e.particles != nullptr ? &e.particles->header
                                    : e.wrench != nullptr  ? &e.wrench->header
                                                           : &e.gripper->header;
  j["t"] = number(header->stamp_s);
  j["seq"] = header->sequence;
  j["status"] = header->status_bits;
  if (e.particles != nullptr) {
    j["observed"] = e.particles->observed_count;
    j["particles"] = e.particles->particle_count;
    if (e.estimate != nullptr) {
      j["estimate"] = {{"msm_beta", number(e.estimate->msm_beta)},
                       {"msm_beta_std", number(e.estimate->msm_beta_std)},
                       {"msm_alpha", number(e.estimate->msm_alpha)},
                       {"alpha_fitted", e.estimate->alpha_fitted},
                       {"steps_per_frame", e.estimate->steps_per_frame},
                       {"rms", number(e.estimate->rms)},
                       {"frames", e.estimate->frames},
                       {"update", status_name(e.estimator_status)}};
    }
  } else if (e.wrench != nullptr) {
    nlohmann::json w = nlohmann::json::array();
    for (double v : e.wrench->wrench) w.push_back(number(v));
    j["wrench"] = w;
  } else {
    j["width"] = number(e.gripper->width_m);
    j["force"] = number(e.gripper->force_n);
  }
  return j;
}

nlohmann::json summary_json(const host::ReplaySummary& s) {
  nlohmann::json devices = nlohmann::json::object();
  for (int d = 0; d < 3; ++d) {
    const host::ReplayDeviceSummary& ds = s.devices[d];
    if (!ds.present) continue;
    const hal::DeviceCounters& c = ds.counters;
    nlohmann::json injected = nlohmann::json::object();
    for (int k = 0; k < hal::kFaultKindCount; ++k) {
      if (ds.injected.injected[k] > 0)
        injected[hal::fault_kind_name(static_cast<hal::FaultKind>(k))] = ds.injected.injected[k];
    }
    devices[host::replay_device_name(static_cast<host::ReplayDevice>(d))] = {
        {"samples", c.samples},         {"dropped", c.dropped},       {"fault_samples", c.fault_samples},
        {"timeouts", c.timeouts},       {"bus_off", c.bus_off},       {"disconnected", c.disconnected},
        {"disconnects", c.disconnects}, {"reconnects", c.reconnects}, {"injected", injected}};
  }
  nlohmann::json j = {{"summary",
                       {{"devices", devices},
                        {"duration", s.duration_s},
                        {"interrupted", s.interrupted},
                        {"skipped_rows", s.skipped_rows}}}};
  if (s.estimated) {
    j["summary"]["estimate"] = {{"msm_beta", number(s.estimate.msm_beta)},
                                {"msm_beta_std", number(s.estimate.msm_beta_std)},
                                {"msm_alpha", number(s.estimate.msm_alpha)},
                                {"alpha_fitted", s.estimate.alpha_fitted},
                                {"steps_per_frame", s.estimate.steps_per_frame},
                                {"unique_minimum", s.estimate.unique_minimum},
                                {"rms", number(s.estimate.rms)},
                                {"frames", s.estimate.frames},
                                {"rejected_frames", s.estimator_rejected_frames},
                                {"empty_frames", s.estimator_empty_frames}};
  }
  return j;
}

std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UsageError("cannot read fault script " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

ReplayCommand::ReplayCommand(CLI::App& parent) {
  app_ = parent.add_subcommand("replay", "Play a recording back through the HAL replay devices");
  app_->footer(
      "Plays the recording's particle frames, wrench.csv and gripper.csv back as a particle observer, a force/torque "
      "sensor and a gripper (the HAL replay mocks), in real time (--speed scales it) or --stepped (as fast as "
      "possible, in recorded order, reproducible), optionally with the faults of a fault script (docs/hal.md; "
      "devices observer, ft, gripper; times from the start of the replay). Estimates msm_beta online from the "
      "delivered frames as a controller would: 21 msm_beta candidates for each model form (msm_alpha 0.3, 0.65 "
      "or 1 at 1, 2 or 4 MSM steps per frame), the form other than alpha 1 at one step taken only when the frames "
      "determine it (BIC; --msm-alpha holds alpha at one step per frame). Writes one JSON object per delivered sample "
      "or device failure to "
      "standard output or -o FILE, the last line a summary; prints the summary on standard error. Ctrl-C stops "
      "early and still writes the summary.");
  app_->add_option("recording", recording_, "recording directory")->required();
  app_->add_flag("--stepped", stepped_, "as fast as possible, on a stepped clock");
  app_->add_option("--speed", speed_, "recorded seconds per real second (default 1)")->check(CLI::PositiveNumber);
  app_->add_option("--faults", faults_, "fault script file");
  app_->add_flag("--no-estimate", no_estimate_, "do not run the online msm_beta estimate");
  app_->add_option("--msm-alpha", msm_alpha_, "hold msm_alpha at this value in (0, 1] (default: chosen online)")
      ->check(CLI::Range(1e-6, 1.0));
  app_->add_option("--settled-row", settled_row_,
                   "add the quasi-static row: candidates relaxed towards equilibrium every frame with at most N MSM "
                   "iterations (for objects that settle between frames; 0: off)")
      ->type_name("N")
      ->capture_default_str();
  app_->add_option("-o,--output", output_, "JSON lines file (written when the replay ends)");
}

int ReplayCommand::run() const {
  const host::Recording recording = host::read_recording(recording_);
  host::ReplayOptions options;
  options.timing.mode = stepped_ ? hal::ReplayMode::stepped : hal::ReplayMode::realtime;
  options.timing.speed = speed_;
  options.estimate = !no_estimate_;
  if (msm_alpha_) {
    options.msm_alpha = *msm_alpha_;
    options.alpha_candidates = 1;
    options.step_candidates = 1;
  }
  options.equilibrium_iterations = settled_row_;
  if (!faults_.empty()) options.fault_script = read_text_file(faults_);

  std::ostringstream buffered;
  std::ostream& out = output_.empty() ? std::cout : buffered;
  g_replay_stop = 0;
  auto old_int = std::signal(SIGINT, request_replay_stop);
  host::ReplaySummary summary;
  try {
    summary = host::replay_recording(
        recording, options, [&](const host::ReplayEvent& e) { out << event_json(e).dump() << '\n'; },
        [] { return g_replay_stop == 0; });
  } catch (const std::invalid_argument& e) {
    std::signal(SIGINT, old_int);
    throw UsageError(e.what());
  }
  std::signal(SIGINT, old_int);
  const nlohmann::json s = summary_json(summary);
  out << s.dump() << '\n';
  if (!output_.empty()) write_file_atomically(output_, buffered.str());
  std::cerr << "pliant replay: " << s["summary"].dump() << '\n';
  return exit_ok;
}

}  // namespace pliant::cli
