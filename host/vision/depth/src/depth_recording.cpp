#include "pliant/vision/depth_recording.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace pliant::vision {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Eigen::Vector3d plan_position(const host::Recording& plan, int frame, int id) {
  if (!plan.observed(frame, id)) return Eigen::Vector3d::Constant(kNaN);
  return {plan.position(frame, id, 0), plan.position(frame, id, 1), plan.position(frame, id, 2)};
}

// The output's header: the plan's metadata without its frames and media.
host::Recording header_of(const host::Recording& plan, const DepthSequenceOptions& options) {
  host::Recording out;
  out.name = plan.name;
  out.dimension = 3;
  out.length_unit = "m";
  out.gravity = plan.gravity;
  out.particle_count = plan.particle_count;
  out.masses = plan.masses;
  out.fixed = plan.fixed;
  out.driven = plan.driven;
  out.files = {{"particles", "particles.csv"}};
  out.wrench_applied_to = plan.wrench_applied_to;
  out.material = plan.material;
  out.meta = plan.meta.is_object() ? plan.meta : nlohmann::json::object();
  out.wrench = plan.wrench;
  out.gripper = plan.gripper;
  out.mesh = plan.mesh;
  nlohmann::json tracking;
  tracking["source"] = "pliant depth tracker";
  tracking["correspondence"] =
      options.tracker.correspondence == Correspondence::point_to_plane ? "point_to_plane" : "nearest_point";
  tracking["msm_beta_prior"] = options.msm_beta;
  tracking["observed_only"] = options.observed_only;
  tracking["reference_frames"] = options.reference_frames;
  out.meta["depth_tracking"] = tracking;
  return out;
}

}  // namespace

void driven_targets_at(const host::Recording& plan, double t_s, std::vector<int>& ids,
                       std::vector<Eigen::Vector3d>& positions) {
  ids.clear();
  positions.clear();
  const int frames = plan.frame_count();
  if (frames == 0) return;
  const auto& times = plan.frame_times_s;
  for (const host::DrivenWindow& window : plan.driven) {
    if (!window.active_at(t_s)) continue;
    Eigen::Vector3d target = Eigen::Vector3d::Constant(kNaN);
    if (t_s <= times.front()) {
      target = plan_position(plan, 0, window.id);
    } else if (t_s >= times.back()) {
      target = plan_position(plan, frames - 1, window.id);
    } else {
      const auto after = static_cast<int>(std::upper_bound(times.begin(), times.end(), t_s) - times.begin());
      const int before = after - 1;
      const double share = (t_s - times[static_cast<std::size_t>(before)]) /
                           (times[static_cast<std::size_t>(after)] - times[static_cast<std::size_t>(before)]);
      target = (1 - share) * plan_position(plan, before, window.id) + share * plan_position(plan, after, window.id);
    }
    ids.push_back(window.id);
    positions.push_back(target);
  }
}

DepthSequenceResult track_depth_sequence(const host::Recording& plan, const std::vector<double>& times_s,
                                         const DepthFrameSource& frames, const PinholeIntrinsics& intrinsics,
                                         const DepthSequenceOptions& options) {
  if (plan.dimension != 3) throw DepthError("plan recording: must be 3D (dimension 3) for depth tracking");
  if (plan.length_unit != "m") throw DepthError("plan recording: length_unit must be \"m\" for depth tracking");
  if (plan.particle_count < 1 || plan.rest_positions.size() != static_cast<std::size_t>(plan.particle_count) * 3) {
    throw DepthError("plan recording: no rest configuration");
  }
  if (times_s.empty()) throw DepthError("depth sequence: no frames");
  for (std::size_t k = 0; k < times_s.size(); ++k) {
    if (!std::isfinite(times_s[k]))
      throw DepthError("depth sequence: time of frame " + std::to_string(k) + " is not finite");
    if (k > 0 && !(times_s[k] > times_s[k - 1])) {
      throw DepthError("depth sequence: frame times must increase strictly (frame " + std::to_string(k) + ")");
    }
  }
  if (!(options.msm_beta >= 0 && options.msm_beta <= 1)) throw DepthError("depth sequence: msm_beta must be in [0, 1]");
  if (!(options.msm_alpha > 0 && options.msm_alpha <= 1))
    throw DepthError("depth sequence: msm_alpha must be in (0, 1]");
  if (!frames) throw DepthError("depth sequence: no frame source");

  const std::unique_ptr<host::HostMsmModel<3>> model = host::build_msm_model<3>(plan, options.setup);
  MsmParams<3, double> params = host::base_params<3>(plan, options.msm_alpha);
  params.msm_beta = options.msm_beta;
  DepthTracker tracker(model->model, params, intrinsics, options.tracker);
  if (!options.rest_normals.empty()) tracker.set_rest_normals(options.rest_normals);

  DepthSequenceResult result;
  result.recording = header_of(plan, options);
  host::Recording& out = result.recording;
  const int n = plan.particle_count;
  const auto per_frame = static_cast<std::size_t>(n) * 3;
  out.frame_times_s = times_s;
  out.positions.assign(times_s.size() * per_frame, kNaN);
  result.views.assign(times_s.size() * static_cast<std::size_t>(n), ParticleView::held);
  result.status.assign(times_s.size() * static_cast<std::size_t>(n), TrackStatus::observed);
  auto write_frame = [&](std::size_t k, bool everything) {
    const Eigen::Vector3d* x = tracker.positions();
    const TrackStatus* status = tracker.core().status;
    std::copy(tracker.view(), tracker.view() + n, result.views.begin() + static_cast<std::ptrdiff_t>(k) * n);
    if (!everything) std::copy(status, status + n, result.status.begin() + static_cast<std::ptrdiff_t>(k) * n);
    for (int i = 0; i < n; ++i) {
      if (!everything && options.observed_only && status[i] != TrackStatus::observed) continue;
      for (int d = 0; d < 3; ++d)
        out.positions[k * per_frame + static_cast<std::size_t>(i) * 3 + static_cast<std::size_t>(d)] = x[i](d);
    }
  };

  std::vector<int> ids;
  std::vector<Eigen::Vector3d> targets;
  // The object is untouched while every tool target is at its rest position.
  const double still_tolerance = 0.05 * static_cast<double>(model->model.spacing);
  auto untouched = [&]() {
    for (std::size_t m = 0; m < ids.size(); ++m) {
      if (!((targets[m] - model->model.rest[ids[m]]).norm() <= still_tolerance)) return false;
    }
    return true;
  };
  bool calibrating = options.reference_frames > 0;
  if (options.reference_frames < 0) throw DepthError("depth sequence: reference_frames must be >= 0");

  const DepthImageView first = frames(0);
  result.alignment = tracker.look(first);
  write_frame(0, true);
  driven_targets_at(plan, times_s[0], ids, targets);
  calibrating = calibrating && untouched();
  if (calibrating) tracker.calibrate(first);
  result.frames.reserve(times_s.size());
  for (std::size_t k = 1; k < times_s.size(); ++k) {
    driven_targets_at(plan, times_s[k], ids, targets);
    const MsmDrivenTargets<3, double> driven{ids.empty() ? nullptr : ids.data(),
                                             targets.empty() ? nullptr : targets.data(), static_cast<int>(ids.size())};
    const DepthImageView view = frames(static_cast<int>(k));
    calibrating = calibrating && static_cast<int>(k) < options.reference_frames && untouched();
    if (calibrating) tracker.calibrate(view);
    result.frames.push_back(tracker.update(view, times_s[k] - times_s[k - 1], driven));
    write_frame(k, false);
  }
  result.calibration_frames = tracker.calibration_frames();
  out.rest_positions.assign(out.positions.begin(), out.positions.begin() + static_cast<std::ptrdiff_t>(per_frame));
  result.counters = tracker.counters();
  result.core = tracker.core().counters;

  std::uint64_t looked = 0;
  for (const auto count : result.counters.by_view) looked += count;
  const std::uint64_t observed = result.counters.by_view[static_cast<std::size_t>(ParticleView::observed)];
  out.meta["depth_tracking"]["frames"] = times_s.size();
  out.meta["depth_tracking"]["empty_frames"] = result.counters.empty_frames;
  out.meta["depth_tracking"]["calibration_frames"] = result.calibration_frames;
  out.meta["depth_tracking"]["observed_share"] =
      looked > 0 ? static_cast<double>(observed) / static_cast<double>(looked) : 0.0;
  return result;
}

DepthEstimateRounds track_and_estimate(const host::Recording& plan, const std::vector<double>& times_s,
                                       const DepthFrameSource& frames, const PinholeIntrinsics& intrinsics,
                                       const DepthSequenceOptions& options, const host::EstimateOptions& estimate,
                                       int rounds, double tolerance) {
  if (rounds < 1) throw DepthError("track_and_estimate: rounds must be >= 1");
  if (!(tolerance >= 0)) throw DepthError("track_and_estimate: tolerance must be >= 0");
  DepthEstimateRounds out;
  DepthSequenceOptions round_options = options;
  for (int round = 0; round < rounds; ++round) {
    out.tracked = track_depth_sequence(plan, times_s, frames, intrinsics, round_options);
    out.priors.push_back(round_options.msm_beta);
    out.estimates.push_back(host::estimate_recording(out.tracked.recording, estimate));
    const double next = std::clamp(out.estimates.back().result.msm_beta, 0.0, 1.0);
    if (std::abs(next - round_options.msm_beta) < tolerance) break;
    round_options.msm_beta = next;
  }
  out.tracked.recording.meta["depth_tracking"]["msm_beta_prior"] = out.priors.back();
  out.tracked.recording.meta["depth_tracking"]["rounds"] = out.priors.size();
  return out;
}

}  // namespace pliant::vision
