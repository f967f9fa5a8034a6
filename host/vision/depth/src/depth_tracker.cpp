#include "pliant/vision/depth_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Eigenvalues>
#include <nanoflann.hpp>

namespace pliant::vision {
namespace {

using Vec = Eigen::Vector3d;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kMaxNeighbours = 64;
constexpr double kDegree = 3.14159265358979323846 / 180.0;
// Median |x| of a zero-mean Gaussian is 0.6745 sd: turns a median distance into a scale.
constexpr double kMedianToSd = 1.0 / 0.6744897501960817;

struct CloudAdaptor {
  const std::vector<Eigen::Vector3f>* points = nullptr;
  std::size_t kdtree_get_point_count() const { return points->size(); }
  float kdtree_get_pt(std::size_t index, std::size_t axis) const {
    return (*points)[index](static_cast<Eigen::Index>(axis));
  }
  template <class Box>
  bool kdtree_get_bbox(Box& /*box*/) const {
    return false;
  }
};
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, CloudAdaptor>, CloudAdaptor, 3,
                                                   std::uint32_t>;

void check_config(const DepthTrackerConfig& c) {
  auto fail = [](const char* what) { throw DepthError(std::string("depth tracker: ") + what); };
  if (c.plane_neighbours < 3 || c.plane_neighbours > kMaxNeighbours) fail("plane_neighbours must be 3..64");
  if (!(std::isfinite(c.gate_m) && c.gate_m >= 0)) fail("gate_m must be finite and >= 0");
  if (!(std::isfinite(c.visibility_margin_m) && c.visibility_margin_m >= 0))
    fail("visibility_margin_m must be finite and >= 0");
  if (c.depth_window < 0 || c.depth_window > 16) fail("depth_window must be 0..16");
  if (!(c.max_view_angle_deg > 0 && c.max_view_angle_deg <= 90)) fail("max_view_angle_deg must be in (0, 90]");
  if (!(c.max_normal_angle_deg > 0 && c.max_normal_angle_deg <= 180)) fail("max_normal_angle_deg must be in (0, 180]");
  if (!(std::isfinite(c.depth_noise_m) && c.depth_noise_m > 0)) fail("depth_noise_m must be finite and > 0");
  if (!(std::isfinite(c.tukey_c) && c.tukey_c > 0)) fail("tukey_c must be finite and > 0");
  if (c.leaf_max_size < 1 || c.leaf_max_size > 256) fail("leaf_max_size must be 1..256");
  const Eigen::Matrix4d pose = c.camera_to_world.matrix();
  if (!pose.allFinite()) fail("camera_to_world is not finite");
  const Eigen::Matrix3d r = c.camera_to_world.linear();
  if ((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-6 || r.determinant() < 0) {
    fail("camera_to_world must be a rigid transform (orthonormal rotation, determinant +1)");
  }
}

// Median of values (reordered); 0 for none.
double median_of(std::vector<double>& values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

const char* particle_view_name(ParticleView view) noexcept {
  switch (view) {
    case ParticleView::observed: return "observed";
    case ParticleView::held: return "held";
    case ParticleView::interior: return "interior";
    case ParticleView::out_of_view: return "out_of_view";
    case ParticleView::no_depth: return "no_depth";
    case ParticleView::behind_surface: return "behind_surface";
    case ParticleView::facing_away: return "facing_away";
    case ParticleView::no_point: return "no_point";
    case ParticleView::normal_mismatch: return "normal_mismatch";
    case ParticleView::down_weighted: return "down_weighted";
  }
  return "unknown";
}

std::vector<Vec> estimate_rest_normals(const MsmModel<3, double>& model, double radius_factor, double surface_offset) {
  if (!model.initialized()) throw DepthError("estimate_rest_normals: the MSM model is not initialised");
  const int n = model.particle_count;
  const double radius = radius_factor * model.spacing;
  std::vector<Vec> normals(static_cast<std::size_t>(n), Vec::Zero());
  for (int i = 0; i < n; ++i) {
    Vec sum = Vec::Zero();
    int count = 0;
    for (int j = 0; j < n; ++j) {
      if (j == i || (model.rest[j] - model.rest[i]).norm() > radius) continue;
      sum += model.rest[j];
      ++count;
    }
    if (count == 0) continue;
    const Vec offset = model.rest[i] - sum / static_cast<double>(count);
    if (offset.norm() >= surface_offset * model.spacing) normals[static_cast<std::size_t>(i)] = offset.normalized();
  }
  return normals;
}

struct DepthTracker::Impl {
  std::vector<unsigned char> tracker_block;
  std::vector<unsigned char> probe_block;
  MsmState<3, double> probe;  // the frame's prediction, computed as tracker_update will
  bool have_prediction = false;
  DepthCloud cloud;
  CloudAdaptor adaptor;
  std::unique_ptr<KdTree> tree;
  std::vector<Vec> rest_normals;
  std::vector<Vec> observation;
  std::vector<double> distance;
  std::vector<double> confidence;
  std::vector<ParticleView> view;
  std::vector<double> scratch;
  // Reference offsets (calibrate): running sums, counts and means.
  std::vector<Vec> offset_sum;
  std::vector<int> offset_count;
  std::vector<Vec> offset;
  int calibration_frames = 0;
  std::vector<Eigen::Quaterniond> identity;  // [cluster_count] rotations of the rest shape
  double gate_m = 0;
  double margin_m = 0;
  double cos_view = 0;
  double cos_normal = 0;
  Eigen::Matrix3d world_to_camera = Eigen::Matrix3d::Identity();  // rotation
  Vec camera_in_world = Vec::Zero();
};

DepthTracker::DepthTracker(const MsmModel<3, double>& model, const MsmParams<3, double>& params,
                           const PinholeIntrinsics& intrinsics, const DepthTrackerConfig& config)
    : model_(model), config_(config), intrinsics_(intrinsics), impl_(std::make_unique<Impl>()) {
  if (!model.initialized()) throw DepthError("depth tracker: the MSM model is not initialised");
  check_intrinsics(intrinsics);
  check_config(config);
  check_cloud_options(config.cloud, intrinsics.width, intrinsics.height);
  Impl& s = *impl_;
  s.tracker_block.resize(std::max<std::size_t>(tracker_workspace_size(model, config.tracker), 1));
  Arena tracker_arena(s.tracker_block.data(), s.tracker_block.size());
  const Status status = tracker_init(tracker_arena, model, params, config.tracker, tracker_);
  if (status != Status::ok) throw DepthError(std::string("depth tracker: tracker_init: ") + status_name(status));
  s.probe_block.resize(std::max<std::size_t>(msm_state_workspace_size(model), 1));
  Arena probe_arena(s.probe_block.data(), s.probe_block.size());
  if (msm_state_init(probe_arena, model, s.probe) != Status::ok)
    throw DepthError("depth tracker: cannot carve the prediction state");

  const auto n = static_cast<std::size_t>(model.particle_count);
  s.observation.assign(n, Vec::Constant(kNaN));
  s.distance.assign(n, kNaN);
  s.confidence.assign(n, 0.0);
  s.view.assign(n, ParticleView::held);
  s.scratch.reserve(n);
  s.offset_sum.assign(n, Vec::Zero());
  s.offset_count.assign(n, 0);
  s.offset.assign(n, Vec::Zero());
  s.identity.assign(static_cast<std::size_t>(model.cluster_count), Eigen::Quaterniond::Identity());
  s.rest_normals = estimate_rest_normals(model);
  s.cloud.reserve(cloud_capacity(intrinsics.width, intrinsics.height, config.cloud));
  s.adaptor.points = &s.cloud.points;
  s.tree = std::make_unique<KdTree>(
      3, s.adaptor,
      nanoflann::KDTreeSingleIndexAdaptorParams(static_cast<std::size_t>(config.leaf_max_size),
                                                nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex));
  const double spacing = static_cast<double>(model.spacing);
  s.gate_m = config.gate_m > 0 ? config.gate_m : 0.5 * spacing;
  s.margin_m = config.visibility_margin_m > 0 ? config.visibility_margin_m : 0.5 * spacing;
  s.cos_view = std::cos(config.max_view_angle_deg * kDegree);
  s.cos_normal = std::cos(config.max_normal_angle_deg * kDegree);
  s.world_to_camera = config.camera_to_world.linear().transpose();
  s.camera_in_world = config.camera_to_world.translation();
}

DepthTracker::~DepthTracker() = default;

void DepthTracker::set_rest_normals(const std::vector<Vec>& normals) {
  if (normals.size() != static_cast<std::size_t>(model_.particle_count)) {
    throw DepthError("depth tracker: " + std::to_string(normals.size()) + " rest normals for " +
                     std::to_string(model_.particle_count) + " particles");
  }
  for (std::size_t i = 0; i < normals.size(); ++i) {
    if (!normals[i].allFinite()) throw DepthError("depth tracker: rest normal " + std::to_string(i) + " is not finite");
    impl_->rest_normals[i] = normals[i].norm() > 0 ? Vec(normals[i].normalized()) : Vec(Vec::Zero());
  }
}

void DepthTracker::reset() noexcept {
  tracker_reset(model_, tracker_);
  impl_->have_prediction = false;
}

const DepthTracker::Vec* DepthTracker::predicted() const noexcept { return impl_->probe.position; }
const DepthTracker::Vec* DepthTracker::observation() const noexcept { return impl_->observation.data(); }
const double* DepthTracker::distance() const noexcept { return impl_->distance.data(); }
const double* DepthTracker::confidence() const noexcept { return impl_->confidence.data(); }
const ParticleView* DepthTracker::view() const noexcept { return impl_->view.data(); }
const DepthTracker::Vec* DepthTracker::rest_normals() const noexcept { return impl_->rest_normals.data(); }
const DepthCloud& DepthTracker::cloud() const noexcept { return impl_->cloud; }
int DepthTracker::calibration_frames() const noexcept { return impl_->calibration_frames; }
const DepthTracker::Vec* DepthTracker::reference_offsets() const noexcept { return impl_->offset.data(); }

void DepthTracker::clear_calibration() noexcept {
  Impl& s = *impl_;
  std::fill(s.offset_sum.begin(), s.offset_sum.end(), Vec::Zero());
  std::fill(s.offset_count.begin(), s.offset_count.end(), 0);
  std::fill(s.offset.begin(), s.offset.end(), Vec::Zero());
  s.calibration_frames = 0;
}

namespace {

// The tracker's state into the prediction state: everything msm_step reads.
void copy_state(const MsmModel<3, double>& model, const MsmState<3, double>& from, MsmState<3, double>& to) {
  const auto n = static_cast<std::size_t>(model.particle_count);
  const auto c = static_cast<std::size_t>(model.cluster_count);
  std::copy(from.position, from.position + n, to.position);
  std::copy(from.velocity, from.velocity + n, to.velocity);
  std::copy(from.driven_now, from.driven_now + n, to.driven_now);
  std::copy(from.rotation, from.rotation + c, to.rotation);
  std::copy(from.plastic, from.plastic + c, to.plastic);
  std::copy(from.relaxed, from.relaxed + c, to.relaxed);
  to.time_s = from.time_s;
  to.steps = from.steps;
}

// The work of one frame's correspondence search, over the cloud and tree already built.
struct Matcher {
  const MsmModel<3, double>& model;
  const DepthTrackerConfig& config;
  const PinholeIntrinsics& k;
  DepthTracker::Impl& s;

  // Metric depth seen at pixel (u, v): the pixel's own when valid, else the nearest surface
  // (smallest valid depth) within depth_window pixels; NaN when none.
  double depth_at(const DepthImageView& image, int u, int v) const {
    const DepthToCloudOptions& o = config.cloud;
    auto metric = [&](int uu, int vv) {
      const std::uint16_t raw = image.at(uu, vv);
      if (raw == 0) return kNaN;
      const double z = static_cast<double>(raw) * o.depth_scale_m;
      return (z >= o.min_depth_m && z <= o.max_depth_m) ? z : kNaN;
    };
    const double own = metric(u, v);
    if (!std::isnan(own)) return own;
    double best = kNaN;
    const int w = config.depth_window;
    for (int vv = std::max(0, v - w); vv <= std::min(image.height - 1, v + w); ++vv) {
      for (int uu = std::max(0, u - w); uu <= std::min(image.width - 1, u + w); ++uu) {
        const double z = metric(uu, vv);
        if (!std::isnan(z) && !(z >= best)) best = z;
      }
    }
    return best;
  }

  // Outward normal of particle i now (world): its rest normal turned by the rotations of the
  // clusters holding it.
  Vec current_normal(int i, const Eigen::Quaterniond* rotation) const {
    const Vec& rest = s.rest_normals[static_cast<std::size_t>(i)];
    Vec sum = Vec::Zero();
    for (int m = model.particle_cluster_begin[i]; m < model.particle_cluster_begin[i + 1]; ++m) {
      sum += rotation[model.particle_clusters[m]] * rest;
    }
    return sum.norm() > 0 ? Vec(sum.normalized()) : rest;
  }

  // The mean over the clusters holding particle i of R_c v (v when i is in no cluster).
  Vec turned(int i, const Eigen::Quaterniond* rotation, const Vec& v) const {
    Vec sum = Vec::Zero();
    const int begin = model.particle_cluster_begin[i];
    const int end = model.particle_cluster_begin[i + 1];
    for (int m = begin; m < end; ++m) sum += rotation[model.particle_clusters[m]] * v;
    return end > begin ? Vec(sum / static_cast<double>(end - begin)) : v;
  }

  // Fills s.view / observation / distance / confidence for positions x (world). With
  // `use_offsets`, each observation loses its particle's reference offset.
  void run(const DepthImageView& image, const Vec* x, const Eigen::Quaterniond* rotation,
           const std::uint8_t* driven_now, bool use_offsets, DepthFrameReport& report) {
    const int n = model.particle_count;
    const PixelRect region =
        config.cloud.region.empty() ? PixelRect{0, 0, image.width, image.height} : config.cloud.region;
    const std::size_t want = static_cast<std::size_t>(config.plane_neighbours);
    std::uint32_t index[kMaxNeighbours];
    float squared[kMaxNeighbours];
    const double gate_sq = s.gate_m * s.gate_m;
    s.scratch.clear();
    for (int i = 0; i < n; ++i) {
      const auto ii = static_cast<std::size_t>(i);
      s.observation[ii] = Vec::Constant(kNaN);
      s.distance[ii] = kNaN;
      s.confidence[ii] = 0;
      ParticleView& view = s.view[ii];
      if (model.fixed[i] != 0 || (driven_now != nullptr && driven_now[i] != 0)) {
        view = ParticleView::held;
        continue;
      }
      if (s.rest_normals[ii].isZero()) {
        view = ParticleView::interior;
        continue;
      }
      const Vec p = s.world_to_camera * (x[i] - s.camera_in_world);
      if (!p.allFinite() || !(p.z() > 1e-9)) {
        view = ParticleView::out_of_view;
        continue;
      }
      const double u = k.fx * p.x() / p.z() + k.cx;
      const double v = k.fy * p.y() / p.z() + k.cy;
      if (!(u >= region.u0 - 0.5 && u < region.u0 + region.width - 0.5 && v >= region.v0 - 0.5 &&
            v < region.v0 + region.height - 0.5)) {
        view = ParticleView::out_of_view;
        continue;
      }
      const double seen = depth_at(image, static_cast<int>(std::lround(u)), static_cast<int>(std::lround(v)));
      if (std::isnan(seen)) {
        view = ParticleView::no_depth;
        continue;
      }
      if (p.z() > seen + s.margin_m) {
        view = ParticleView::behind_surface;
        continue;
      }
      const Vec normal = s.world_to_camera * current_normal(i, rotation);
      if (normal.dot(-p.normalized()) < s.cos_view) {
        view = ParticleView::facing_away;
        continue;
      }
      const float query[3] = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
      const std::size_t found = s.tree->knnSearch(query, want, index, squared);
      std::size_t inside = 0;
      while (inside < found && static_cast<double>(squared[inside]) <= gate_sq) ++inside;
      const bool plane = config.correspondence == Correspondence::point_to_plane;
      if (inside == 0 || (plane && inside < 3)) {
        view = ParticleView::no_point;
        continue;
      }
      Vec observed = Vec::Zero();
      bool have_normal = inside >= 3;
      Vec surface_normal = Vec::Zero();
      Vec centroid = Vec::Zero();
      if (have_normal) {
        for (std::size_t m = 0; m < inside; ++m) centroid += s.cloud.points[index[m]].cast<double>();
        centroid /= static_cast<double>(inside);
        Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
        for (std::size_t m = 0; m < inside; ++m) {
          const Vec d = s.cloud.points[index[m]].cast<double>() - centroid;
          scatter.noalias() += d * d.transpose();
        }
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
        solver.computeDirect(scatter);
        surface_normal = solver.eigenvectors().col(0);
        have_normal = surface_normal.allFinite() && surface_normal.norm() > 0.5;
        if (have_normal && surface_normal.dot(centroid) > 0) surface_normal = -surface_normal;  // toward the camera
      }
      if (have_normal && surface_normal.dot(normal) < s.cos_normal) {
        view = ParticleView::normal_mismatch;
        continue;
      }
      if (plane) {
        if (!have_normal) {
          view = ParticleView::no_point;
          continue;
        }
        observed = p - surface_normal.dot(p - centroid) * surface_normal;
      } else {
        // The mean of the nearest points: a point correspondence with the noise of one point
        // averaged away (its bias toward the sampling is a shape effect the offsets remove).
        for (std::size_t m = 0; m < inside; ++m) observed += s.cloud.points[index[m]].cast<double>();
        observed /= static_cast<double>(inside);
      }
      Vec world = config.camera_to_world * observed;
      if (use_offsets && s.offset_count[ii] > 0) world -= turned(i, rotation, s.offset[ii]);
      const double distance = (world - x[i]).norm();
      s.observation[ii] = world;
      s.distance[ii] = distance;
      view = ParticleView::observed;
      s.scratch.push_back(distance);
    }

    // Tukey's biweight on the correspondence distances.
    const double median = median_of(s.scratch);
    const double scale = std::max(config.depth_noise_m, median * kMedianToSd);
    const double cutoff = config.tukey_c * scale;
    report.median_distance_m = median;
    report.correspondence_scale_m = scale;
    for (int i = 0; i < n; ++i) {
      const auto ii = static_cast<std::size_t>(i);
      if (s.view[ii] != ParticleView::observed) continue;
      const double r = s.distance[ii] / cutoff;
      if (!(r < 1)) {
        s.view[ii] = ParticleView::down_weighted;
        s.observation[ii] = Vec::Constant(kNaN);
        continue;
      }
      const double taper = 1 - r * r;
      s.confidence[ii] = taper * taper;
    }
    report.by_view.fill(0);
    for (int i = 0; i < n; ++i) ++report.by_view[static_cast<std::size_t>(s.view[static_cast<std::size_t>(i)])];
    report.observed = report.by_view[static_cast<std::size_t>(ParticleView::observed)];
  }
};

}  // namespace

DepthFrameReport DepthTracker::look(const DepthImageView& depth) {
  check_depth_input(depth, intrinsics_, config_.cloud);
  DepthFrameReport report;
  Impl& s = *impl_;
  report.points = depth_to_cloud_unchecked(depth, intrinsics_, config_.cloud, s.cloud);
  s.tree->buildIndex();
  Matcher{model_, config_, intrinsics_, s}.run(depth, tracker_.state.position, tracker_.state.rotation,
                                               tracker_.state.driven_now, true, report);
  return report;
}

DepthFrameReport DepthTracker::calibrate(const DepthImageView& depth) {
  check_depth_input(depth, intrinsics_, config_.cloud);
  DepthFrameReport report;
  Impl& s = *impl_;
  report.points = depth_to_cloud_unchecked(depth, intrinsics_, config_.cloud, s.cloud);
  if (report.points == 0) return report;
  s.tree->buildIndex();
  Matcher{model_, config_, intrinsics_, s}.run(depth, model_.rest, s.identity.data(), nullptr, false, report);
  for (int i = 0; i < model_.particle_count; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    if (s.view[ii] != ParticleView::observed) continue;
    s.offset_sum[ii] += s.observation[ii] - model_.rest[i];
    ++s.offset_count[ii];
    s.offset[ii] = s.offset_sum[ii] / static_cast<double>(s.offset_count[ii]);
  }
  ++s.calibration_frames;
  return report;
}

DepthFrameReport DepthTracker::update(const DepthImageView& depth, double dt_s,
                                      const MsmDrivenTargets<3, double>& driven) {
  check_depth_input(depth, intrinsics_, config_.cloud);
  DepthFrameReport report;
  Impl& s = *impl_;
  report.points = depth_to_cloud_unchecked(depth, intrinsics_, config_.cloud, s.cloud);

  TrackerFrame<3, double> frame;
  frame.dt = dt_s;
  frame.driven = driven;
  frame.observed = s.observation.data();
  frame.confidence = s.confidence.data();

  // The prediction tracker_update is about to make, from a copy of its state.
  copy_state(model_, tracker_.state, s.probe);
  MsmStepInput<3, double> step;
  step.dt = dt_s;
  step.driven = driven;
  const Status predicted = msm_step(model_, tracker_.params, step, s.probe);
  s.have_prediction = predicted == Status::ok || predicted == Status::non_finite_input;

  if (s.have_prediction && report.points > 0) {
    s.tree->buildIndex();
    Matcher{model_, config_, intrinsics_, s}.run(depth, s.probe.position, s.probe.rotation, s.probe.driven_now, true,
                                                 report);
  } else {
    // No depth (or a frame the core will refuse): no observation for anyone.
    report.by_view.fill(0);
    for (int i = 0; i < model_.particle_count; ++i) {
      const auto ii = static_cast<std::size_t>(i);
      s.observation[ii] = Vec::Constant(kNaN);
      s.distance[ii] = kNaN;
      s.confidence[ii] = 0;
      const bool held = model_.fixed[i] != 0 || (s.have_prediction && s.probe.driven_now[i] != 0);
      s.view[ii] =
          held ? ParticleView::held : (s.rest_normals[ii].isZero() ? ParticleView::interior : ParticleView::no_depth);
      ++report.by_view[static_cast<std::size_t>(s.view[ii])];
    }
  }

  report.status = tracker_update(model_, tracker_, frame);
  if (report.status == Status::invalid_argument) {
    ++counters_.refused_frames;
    return report;
  }
  ++counters_.frames;
  if (report.points == 0) ++counters_.empty_frames;
  for (std::size_t v = 0; v < report.by_view.size(); ++v)
    counters_.by_view[v] += static_cast<std::uint64_t>(report.by_view[v]);
  return report;
}

}  // namespace pliant::vision
