#include "hil_squeeze.hpp"

#include <cmath>
#include <ctime>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/mock/mock_particle_observer.hpp"
#include "pliant/hal/mock/simulated_grasp.hpp"
#include "pliant/host/msm_setup.hpp"

namespace pliant::hil {
namespace {

constexpr double kPeriod_s = 0.001;  // the HIL's control period: the plant relaxes once per period

void require(bool ok, const std::string& what) {
  if (!ok) throw std::runtime_error("hil squeeze: " + what);
}

// CPU seconds of the calling thread (the online update runs on one thread; a shared machine's
// load does not count).
double thread_cpu_s() {
  timespec now{};
  (void)clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

// One frame as the recording keeps it: every particle's observed position, and the driven ones
// (within the contact band of a jaw plane) moved onto their plane and marked.
struct SqueezeFrame {
  double t_s = 0;
  std::vector<double> positions;  // [particle_count x 3]
  std::vector<bool> driven;       // [particle_count]
};

SqueezeFrame contact_frame(const hal::ParticleFrame& frame, double width_m, double band_m) {
  SqueezeFrame out;
  out.t_s = frame.header.stamp_s;
  const auto n = static_cast<std::size_t>(frame.particle_count);
  out.positions.assign(frame.positions, frame.positions + 3 * n);
  out.driven.assign(n, false);
  const double plane_a = -0.5 * width_m;
  const double plane_b = 0.5 * width_m;
  for (std::size_t i = 0; i < n; ++i) {
    double& x = out.positions[3 * i];
    if (!std::isfinite(x)) continue;
    const bool at_a = x <= plane_a + band_m;
    const bool at_b = x >= plane_b - band_m;
    if (!at_a && !at_b) continue;
    x = at_a ? plane_a : plane_b;
    out.driven[i] = true;
  }
  return out;
}

// One driven window per particle and run of consecutive frames in which it was driven.
std::vector<DrivenWindow> driven_windows(const std::vector<SqueezeFrame>& frames, int particle_count) {
  std::vector<DrivenWindow> windows;
  for (int i = 0; i < particle_count; ++i) {
    const auto u = static_cast<std::size_t>(i);
    std::size_t k = 0;
    while (k < frames.size()) {
      if (!frames[k].driven[u]) {
        ++k;
        continue;
      }
      DrivenWindow window;
      window.id = i;
      window.from_s = frames[k].t_s;
      while (k < frames.size() && frames[k].driven[u]) window.to_s = frames[k++].t_s;
      windows.push_back(window);
    }
  }
  return windows;
}

host::Recording to_recording(const std::string& name, const std::vector<SqueezeFrame>& frames, int particle_count) {
  host::Recording recording;
  recording.name = name;
  recording.dimension = 3;
  recording.length_unit = "m";
  recording.particle_count = particle_count;
  recording.masses.assign(static_cast<std::size_t>(particle_count), 1.0);
  recording.driven = driven_windows(frames, particle_count);
  for (const SqueezeFrame& frame : frames) {
    recording.frame_times_s.push_back(frame.t_s);
    recording.positions.insert(recording.positions.end(), frame.positions.begin(), frame.positions.end());
  }
  host::finalize_recording(recording);
  return recording;
}

}  // namespace

host::Recording record_squeeze(const HilObject& object, const SqueezeOptions& options) {
  hal::ManualClock clock(0.0);
  hal::SimulatedGrasp plant(clock);
  hal::SimulatedGraspConfig sim;
  sim.object = object.object;
  sim.period_s = kPeriod_s;
  require(plant.configure(sim) == hal::HalStatus::ok, "plant configure");
  sim.initial_width_m = plant.extent_m();  // the jaws start touching the object
  require(plant.configure(sim) == hal::HalStatus::ok, "plant configure");
  hal::MockParticleObserverConfig camera;
  camera.period_s = 1.0 / options.camera_rate_hz;
  camera.noise_m = options.camera_noise_m;
  camera.seed = options.seed;
  hal::MockParticleObserver observer(plant, clock, camera);
  require(observer.configure() == hal::HalStatus::ok && observer.start() == hal::HalStatus::ok, "camera start");

  const double band_m = options.contact_band * plant.model().spacing;
  const double final_width_m = plant.extent_m() * (1 - options.closure_fraction);
  std::vector<SqueezeFrame> frames;
  bool squeezing = false;
  for (std::int64_t cycle = 1;; ++cycle) {
    (void)clock.set(static_cast<double>(cycle) * kPeriod_s);
    hal::ParticleFrame frame;
    if (observer.read(frame) == hal::HalStatus::ok) {
      require(frame.particle_count == plant.particle_count(), "frame size");
      frames.push_back(contact_frame(frame, plant.width_m(), band_m));
      // The squeeze ends with the first frame after the jaws stopped.
      if (squeezing && !plant.moving()) break;
      if (!squeezing && static_cast<int>(frames.size()) == options.rest_frames) {
        plant.command_move(final_width_m, options.speed_m_per_s, std::numeric_limits<double>::infinity());
        squeezing = true;
      }
    }
    require(cycle < 100000000, "the squeeze did not end");
  }
  require(plant.counters().step_errors == 0, "plant msm_step failed");
  return to_recording(object.name, frames, plant.particle_count());
}

OnlineRun run_online(const host::Recording& recording, const OnlineDeformabilityConfig& config) {
  using Vec = Eigen::Vector3d;
  const std::unique_ptr<host::HostMsmModel<3>> model = host::build_msm_model<3>(recording, host::MsmSetupOptions{});
  OnlineRun run;
  run.workspace_bytes = online_deformability_workspace_size(model->model, config);
  std::vector<unsigned char> block(run.workspace_bytes);
  Arena arena(block.data(), block.size());
  OnlineDeformability<3, double> online;
  host::require_ok(online_deformability_init(arena, model->model, host::base_params<3>(recording, 1.0), config, online),
                   "online estimator");
  const auto n = static_cast<std::size_t>(recording.particle_count);
  std::vector<Vec> observed(n);
  std::vector<int> ids;
  std::vector<Vec> targets;
  ids.reserve(n);
  targets.reserve(n);
  double total_s = 0;
  for (int k = 1; k < recording.frame_count(); ++k) {
    const double t = recording.frame_times_s[static_cast<std::size_t>(k)];
    for (std::size_t i = 0; i < n; ++i) {
      for (int d = 0; d < 3; ++d) observed[i](d) = recording.position(k, static_cast<int>(i), d);
    }
    ids.clear();
    targets.clear();
    for (const DrivenWindow& window : recording.driven) {
      if (!window.active_at(t)) continue;
      ids.push_back(window.id);
      targets.push_back(observed[static_cast<std::size_t>(window.id)]);
    }
    const MsmDrivenTargets<3, double> driven{ids.data(), targets.data(), static_cast<int>(ids.size())};
    const double dt = t - recording.frame_times_s[static_cast<std::size_t>(k - 1)];
    const double start_s = thread_cpu_s();
    const Status status = online_deformability_update(model->model, online, dt, driven, observed.data());
    total_s += thread_cpu_s() - start_s;
    require(status == Status::ok || status == Status::no_observations,
            std::string("online update: ") + status_name(status));
    ++run.frames;
  }
  run.estimate = online_deformability_estimate(online);
  run.unrelaxed = online.unrelaxed;
  run.update_cpu_us = run.frames > 0 ? 1e6 * total_s / run.frames : 0;
  return run;
}

host::EstimateReport run_offline(const host::Recording& recording, bool radius_auto) {
  host::EstimateOptions options;
  options.input_noise_samples = 0;
  options.cluster_radius_auto = radius_auto;
  return host::estimate_recording(recording, options);
}

}  // namespace pliant::hil
