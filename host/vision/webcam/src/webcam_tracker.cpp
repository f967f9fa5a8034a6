// The tracking loop: flow observations, the core tracker's correction, roles at the end.
#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pliant/core/msm_model.hpp"
#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_tracker.hpp"

namespace pliant::vision::webcam {
namespace {

using Vec2 = Eigen::Matrix<double, 2, 1>;
constexpr double kNaN = ParticleObservation::kNaN;
constexpr double kToolMotionPx = 1.0;

int nearest_particle(const ParticleGrid& grid, const cv::Point2d& point) {
  int best = 0;
  double best_distance = HUGE_VAL;
  for (int i = 0; i < grid.size(); ++i) {
    const cv::Point2d d = grid.positions[static_cast<std::size_t>(i)] - point;
    if (std::hypot(d.x, d.y) < best_distance) {
      best_distance = std::hypot(d.x, d.y);
      best = i;
    }
  }
  return best;
}

// The tracker's free MSM model of the grid and the memory it lives in.
struct TrackerModel {
  std::unique_ptr<unsigned char[]> model_block;
  std::unique_ptr<unsigned char[]> tracker_block;
  MsmModel<2, double> model;
  Tracker<2, double> tracker;
};

std::string status_text(const char* what, Status status) { return std::string(what) + ": " + status_name(status); }

void build_tracker(const ParticleGrid& grid, const TrackOptions& options, TrackerModel& out) {
  const int n = grid.size();
  std::vector<double> rest(static_cast<std::size_t>(2 * n));
  for (int i = 0; i < n; ++i) {
    rest[static_cast<std::size_t>(2 * i)] = grid.positions[static_cast<std::size_t>(i)].x;
    rest[static_cast<std::size_t>(2 * i + 1)] = grid.positions[static_cast<std::size_t>(i)].y;
  }
  // Every particle may be driven: the tool particle is only known as the video goes on.
  std::vector<int> drivable(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) drivable[static_cast<std::size_t>(i)] = i;
  MsmModelConfig<2, double> config;
  config.particle_count = n;
  config.rest_positions = rest.data();
  config.drivable_ids = drivable.data();
  config.drivable_count = n;
  config.clusters.layout = ClusterLayout::k_nearest;
  config.clusters.k = std::min(8, n - 1);
  const std::size_t model_bytes = msm_model_workspace_size(config);
  out.model_block = std::make_unique<unsigned char[]>(std::max<std::size_t>(model_bytes, 1));
  Arena model_arena(out.model_block.get(), model_bytes);
  const Status model_status = msm_model_init(model_arena, config, out.model);
  if (model_status != Status::ok) {
    throw InputError(status_text("the particles cannot form an MSM model", model_status));
  }
  MsmParams<2, double> params;
  params.msm_alpha = 1;
  params.msm_beta = options.tracker_msm_beta;
  const std::size_t tracker_bytes = tracker_workspace_size(out.model, options.tracker);
  out.tracker_block = std::make_unique<unsigned char[]>(std::max<std::size_t>(tracker_bytes, 1));
  Arena tracker_arena(out.tracker_block.get(), tracker_bytes);
  const Status tracker_status = tracker_init(tracker_arena, out.model, params, options.tracker, out.tracker);
  if (tracker_status != Status::ok) throw InputError(status_text("tracker settings refused", tracker_status));
}

// Per particle, its largest distance from its seed in the frames where the camera saw it. Where
// it was not seen the tracker's position is the MSM prior's guess, run without any support
// (roles are chosen from this motion), and can drift: a still base whose particles are often
// unseen at the object's edge would look as if it moved. A particle never seen keeps the
// largest distance of its tracked positions.
std::vector<double> observed_motion(const TrackResult& result) {
  const int n = result.particle_count();
  std::vector<double> seen_motion(static_cast<std::size_t>(n), 0.0);
  std::vector<double> any_motion(static_cast<std::size_t>(n), 0.0);
  std::vector<bool> ever_seen(static_cast<std::size_t>(n), false);
  for (int f = 0; f < result.frame_count(); ++f) {
    for (int i = 0; i < n; ++i) {
      const std::size_t k = static_cast<std::size_t>(i);
      const cv::Point2d d = result.tracked[result.at(f, i)] - result.grid.positions[k];
      const double distance = std::hypot(d.x, d.y);
      any_motion[k] = std::max(any_motion[k], distance);
      if (f == 0 || result.observed[result.at(f, i)] != 0) {
        seen_motion[k] = std::max(seen_motion[k], distance);
        if (f > 0) ever_seen[k] = true;
      }
    }
  }
  for (std::size_t k = 0; k < seen_motion.size(); ++k) {
    if (!ever_seen[k]) seen_motion[k] = any_motion[k];
  }
  return seen_motion;
}

}  // namespace

void check_track_options(const TrackOptions& options) {
  check_advection_config(options.advection);
  if (!(options.tracker_msm_beta >= 0 && options.tracker_msm_beta <= 1)) {
    throw InputError("--track-beta must be in [0, 1]");
  }
}

TrackResult track_particles(FrameReader& reader, const Region& region, const GridSpec& grid_spec,
                            const TrackOptions& options) {
  check_track_options(options);
  TrackResult result;
  result.source = reader.source().name();
  result.source_fps_hz = reader.source().fps();
  result.rate_hz = reader.rate_hz();
  result.options = options;
  result.options.progress = nullptr;
  result.options.progress_context = nullptr;

  GreyFrame frame;
  if (!reader.next(frame)) throw InputError(result.source + ": no frame could be decoded");
  result.frame_size = frame.grey.size();
  result.grid = seed_particles(region, grid_spec, result.frame_size);
  const ParticleGrid& grid = result.grid;
  const int n = grid.size();
  const std::size_t count = static_cast<std::size_t>(n);

  TrackerModel tm;
  build_tracker(grid, options, tm);
  Tracker<2, double>& tracker = tm.tracker;

  AdvectionConfig advection = options.advection;
  if (advection.dis_finest_scale < 0) {
    advection.dis_finest_scale = dis_finest_scale_for_spacing(std::min(grid.spacing_x_px, grid.spacing_y_px));
  }
  result.options.advection = advection;
  FlowAdvector advector(options.flow, advection);

  // The tool particle drives the tracker's prior while its observation is usable: without it
  // the free model would smooth away the deformation peak under the tool and reject the very
  // observations that show it. Given by option, or else the boundary particle that has moved
  // farthest so far (at least kToolMotionPx).
  int given_tool = -1;
  if (options.driven.kind == DrivenSpec::Kind::id) {
    if (options.driven.id < 0 || options.driven.id >= n) {
      throw InputError("--driven: particle " + std::to_string(options.driven.id) + " out of range 0.." +
                       std::to_string(n - 1));
    }
    given_tool = options.driven.id;
  } else if (options.driven.kind == DrivenSpec::Kind::point) {
    given_tool = nearest_particle(grid, options.driven.point);
  }
  std::vector<int> boundary;
  for (GridSide side : {GridSide::top, GridSide::bottom, GridSide::left, GridSide::right}) {
    for (int id : grid_side_particles(grid, side)) boundary.push_back(id);
  }
  advector.start(frame.grey, grid.positions);

  const int expected = reader.expected_frames();
  const auto report = [&](int done) {
    if (options.progress != nullptr) options.progress(options.progress_context, done, expected);
  };
  const auto record = [&](const GreyFrame& f, const std::vector<ParticleObservation>* observations) {
    result.times_s.push_back(f.t_s);
    result.source_index.push_back(f.source_index);
    for (int i = 0; i < n; ++i) {
      const std::size_t k = static_cast<std::size_t>(i);
      const Vec2& p = tracker.state.position[i];
      result.tracked.emplace_back(p(0), p(1));
      const bool used = observations == nullptr || tracker.weight[i] > 0 || tracker.state.driven_now[i] != 0;
      result.observed.push_back(used ? 1 : 0);
      result.status.push_back(
          static_cast<std::uint8_t>(observations == nullptr ? TrackStatus::observed : tracker.status[i]));
      if (observations == nullptr) {
        result.check.push_back(static_cast<std::uint8_t>(ObservationKind::advected));
        result.fb_error_px.push_back(0.0f);
        result.similarity.push_back(1.0f);
      } else {
        const ParticleObservation& o = (*observations)[k];
        result.check.push_back(static_cast<std::uint8_t>(o.kind));
        result.fb_error_px.push_back(static_cast<float>(o.fb_error_px));
        result.similarity.push_back(static_cast<float>(o.similarity));
      }
    }
  };
  record(frame, nullptr);
  report(1);

  std::vector<cv::Point2d> positions(grid.positions), predicted(count);
  std::vector<std::uint8_t> seen(count, 1);
  std::vector<ParticleObservation> observations;
  std::vector<Vec2> observed(count, Vec2::Zero());
  double previous_t = frame.t_s;
  while (reader.next(frame)) {
    const double dt = frame.t_s - previous_t;
    if (!(dt > 0)) throw std::runtime_error(frame.label + ": frame time does not increase");
    for (std::size_t i = 0; i < count; ++i) {
      const Vec2 guess = tracker.state.position[i] + dt * tracker.state.velocity[i];
      predicted[i] = cv::Point2d(guess(0), guess(1));
    }
    int tool = given_tool;
    if (tool < 0) {
      double farthest = kToolMotionPx;
      for (int id : boundary) {
        const Vec2 moved = tracker.state.position[id] - tm.model.rest[id];
        if (moved.norm() > farthest) {
          farthest = moved.norm();
          tool = id;
        }
      }
    }
    advector.set_peak(tool);
    advector.observe(frame.grey, positions, predicted, seen, observations);
    for (std::size_t i = 0; i < count; ++i) {
      const ParticleObservation& o = observations[i];
      observed[i] = o.usable() ? Vec2(o.position.x, o.position.y) : Vec2(kNaN, kNaN);
    }
    Vec2 tool_target = Vec2::Zero();
    TrackerFrame<2, double> in;
    in.dt = dt;
    in.observed = observed.data();
    if (tool >= 0 && observations[static_cast<std::size_t>(tool)].usable()) {
      tool_target = observed[static_cast<std::size_t>(tool)];
      in.driven = {&tool, &tool_target, 1};
    }
    const Status status = tracker_update(tm.model, tracker, in);
    if (status != Status::ok && status != Status::no_observations) {
      throw std::runtime_error(status_text((frame.label + ": tracker update failed").c_str(), status));
    }
    for (std::size_t i = 0; i < count; ++i) {
      const Vec2& p = tracker.state.position[i];
      positions[i] = cv::Point2d(p(0), p(1));
      seen[i] = tracker.weight[i] > 0 || tracker.state.driven_now[i] != 0 ? 1 : 0;
    }
    advector.commit(positions, seen);
    record(frame, &observations);
    previous_t = frame.t_s;
    report(result.frame_count());
  }
  if (result.frame_count() < 2) {
    throw InputError(result.source + ": only one frame; tracking needs at least two");
  }
  result.counters = tracker.counters;

  result.motion_px = observed_motion(result);
  result.roles = choose_roles(grid, result.motion_px, options.support, options.driven);
  return result;
}

}  // namespace pliant::vision::webcam
