// Advection, forward-backward and appearance checks, and the search for hidden particles.
#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/video/tracking.hpp>

#include "pliant/vision/webcam_advection.hpp"
#include "pliant/vision/webcam_error.hpp"

namespace pliant::vision::webcam {
namespace {

bool inside(const cv::Mat& frame, const cv::Point2d& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && p.x >= -0.5 && p.y >= -0.5 && p.x <= frame.cols - 0.5 &&
         p.y <= frame.rows - 0.5;
}

// The bounding box of the finite points of `a` and `b` grown by margin_px and clipped to `frame`;
// the whole frame when margin_px < 0 or no point is finite.
cv::Rect region_around(const std::vector<cv::Point2d>& a, const std::vector<cv::Point2d>& b, int margin_px,
                       cv::Size frame) {
  const cv::Rect whole(cv::Point(0, 0), frame);
  if (margin_px < 0) return whole;
  double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL;
  for (const std::vector<cv::Point2d>* points : {&a, &b}) {
    for (const cv::Point2d& p : *points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
      x0 = std::min(x0, p.x);
      y0 = std::min(y0, p.y);
      x1 = std::max(x1, p.x);
      y1 = std::max(y1, p.y);
    }
  }
  if (!(x0 <= x1 && y0 <= y1)) return whole;
  const double m = margin_px;
  const auto clamp = [](double v, int hi) { return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(hi))); };
  const cv::Point top_left(clamp(std::floor(x0 - m), frame.width), clamp(std::floor(y0 - m), frame.height));
  const cv::Point bottom_right(clamp(std::ceil(x1 + m) + 1, frame.width), clamp(std::ceil(y1 + m) + 1, frame.height));
  const cv::Rect region(top_left, bottom_right);
  return region.area() > 0 ? region : whole;
}

}  // namespace

const char* observation_kind_name(ObservationKind kind) {
  switch (kind) {
    case ObservationKind::advected: return "advected";
    case ObservationKind::found: return "found";
    case ObservationKind::inconsistent: return "inconsistent";
    case ObservationKind::dissimilar: return "dissimilar";
    case ObservationKind::outside: return "outside";
    case ObservationKind::not_found: return "not_found";
  }
  return "unknown";
}

void check_advection_config(const AdvectionConfig& c) {
  if (c.window_px < 1 || c.window_px > 101) throw InputError("--window must be between 1 and 101 px");
  if (!(std::isfinite(c.fb_threshold_px) && c.fb_threshold_px > 0)) throw InputError("--fb-threshold must be > 0 px");
  if (!(c.min_similarity > -1 && c.min_similarity <= 1)) throw InputError("--min-similarity must be in (-1, 1]");
  if (c.patch_px < 5 || c.patch_px > 101 || c.patch_px % 2 == 0) throw InputError("patch size must be odd, 5..101 px");
  if (!(c.refresh_similarity >= c.min_similarity && c.refresh_similarity <= 1)) {
    throw InputError("the template refresh similarity must be in [min similarity, 1]");
  }
  if (c.search_radius_px < 0 || c.search_radius_px > 50) throw InputError("--search-radius must be 0..50 px");
  if (c.refine_window_px != 0 && (c.refine_window_px < 3 || c.refine_window_px > 51 || c.refine_window_px % 2 == 0)) {
    throw InputError("--refine-window must be 0 (off) or odd, 3..51 px");
  }
  if (c.peak_refine_window_px < 3 || c.peak_refine_window_px > 51 || c.peak_refine_window_px % 2 == 0) {
    throw InputError("the tool's refining window must be odd, 3..51 px");
  }
  if (c.dis_finest_scale < -1 || c.dis_finest_scale > 4)
    throw InputError("DIS finest scale must be 0..4 (or -1: from the spacing)");
  if (c.flow_margin_px != -1 && (c.flow_margin_px < 16 || c.flow_margin_px > 4096)) {
    throw InputError("--flow-margin must be 16..4096 px, or -1 (the whole frame)");
  }
}

FlowAdvector::FlowAdvector(FlowMethod method, const AdvectionConfig& config)
    : flow_(method, config.dis_finest_scale < 0 ? 2 : config.dis_finest_scale), config_(config) {
  check_advection_config(config_);
}

void FlowAdvector::start(const cv::Mat& grey, const std::vector<cv::Point2d>& positions) {
  CV_Assert(grey.type() == CV_8UC1);
  grey.copyTo(previous_);
  templates_.assign(positions.size(), cv::Mat());
  for (std::size_t i = 0; i < positions.size(); ++i)
    extract_patch(previous_, positions[i], config_.patch_px, templates_[i]);
}

PatchMatch FlowAdvector::search(const cv::Mat& templ, const cv::Point2d& a, const cv::Point2d& b) const {
  PatchMatch best;
  best.position = cv::Point2d(ParticleObservation::kNaN, ParticleObservation::kNaN);
  for (const cv::Point2d& centre : {a, b}) {
    if (!inside(next_, centre)) continue;
    const PatchMatch match = search_patch(next_, templ, centre, config_.search_radius_px);
    if (match.similarity > best.similarity && inside(next_, match.position)) best = match;
    // The same centre twice (prediction = advection) needs one search only.
    if (std::hypot(a.x - b.x, a.y - b.y) < 0.5) break;
  }
  return best;
}

void FlowAdvector::observe(const cv::Mat& next, const std::vector<cv::Point2d>& positions,
                           const std::vector<cv::Point2d>& predicted, const std::vector<std::uint8_t>& seen,
                           std::vector<ParticleObservation>& out) {
  const std::size_t n = templates_.size();
  CV_Assert(next.type() == CV_8UC1 && next.size() == previous_.size() && positions.size() == n &&
            predicted.size() == n && seen.size() == n);
  next.copyTo(next_);
  region_ = region_around(positions, predicted, config_.flow_margin_px, previous_.size());
  previous_(region_).copyTo(previous_region_);  // DIS needs continuous images
  next_(region_).copyTo(next_region_);
  flow_.compute(previous_region_, next_region_, forward_);
  if (config_.forward_backward) {
    flow_.compute(next_region_, previous_region_, backward_);
  } else {
    backward_.release();
  }
  out.assign(n, ParticleObservation{});
  advected_.assign(n, cv::Point2d(ParticleObservation::kNaN, ParticleObservation::kNaN));
  for (std::size_t i = 0; i < n; ++i) {
    if (inside(previous_, positions[i])) advected_[i] = positions[i] + mean_flow(forward_, positions[i]);
  }
  if (config_.refine_window_px > 0) refine(positions);
  for (std::size_t i = 0; i < n; ++i) {
    ParticleObservation& o = out[i];
    const cv::Point2d p = positions[i];
    const cv::Point2d expected = std::isfinite(predicted[i].x) && std::isfinite(predicted[i].y) ? predicted[i] : p;
    cv::Point2d q = expected;
    if (inside(previous_, p)) q = advected_[i];
    if (!inside(next_, q) && !inside(next_, expected)) {
      o.kind = ObservationKind::outside;
      continue;
    }
    if (seen[i] != 0) {
      if (!inside(previous_, p) || !inside(next_, q)) {
        o.kind = ObservationKind::outside;
        continue;
      }
      if (config_.forward_backward) {
        const cv::Point2d back = q + mean_flow(backward_, q);
        o.fb_error_px = std::hypot(back.x - p.x, back.y - p.y);
      }
      extract_patch(next_, q, config_.patch_px, patch_);
      o.similarity = patch_similarity(templates_[i], patch_);
      const bool consistent = !config_.forward_backward || o.fb_error_px <= config_.fb_threshold_px;
      if (consistent && o.similarity >= config_.min_similarity) {
        o.kind = ObservationKind::advected;
        o.position = q;
      } else {
        o.kind = consistent ? ObservationKind::dissimilar : ObservationKind::inconsistent;
      }
      continue;
    }
    // Not seen in the previous frame: look for its template.
    const PatchMatch match = search(templates_[i], q, expected);
    o.similarity = match.similarity;
    if (match.similarity >= config_.min_similarity) {
      o.kind = ObservationKind::found;
      o.position = match.position;
    } else {
      o.kind = ObservationKind::not_found;
    }
  }
  last_similarity_.resize(n);
  for (std::size_t i = 0; i < n; ++i) last_similarity_[i] = out[i].similarity;
}

cv::Point2d FlowAdvector::mean_flow(const cv::Mat& flow, const cv::Point2d& p) const {
  const cv::Point2d corner(region_.x, region_.y);
  return window_mean_flow(flow, p - corner, config_.window_px);
}

void FlowAdvector::refine(const std::vector<cv::Point2d>& positions) {
  refine_with(positions, false, config_.refine_window_px);
  if (peak_ >= 0 && static_cast<std::size_t>(peak_) < positions.size()) {
    refine_with(positions, true, std::min(config_.peak_refine_window_px, config_.refine_window_px));
  }
}

// Lucas-Kanade from positions to advected_ with a window_px window: the peak particle alone
// (peak) or every other particle.
void FlowAdvector::refine_with(const std::vector<cv::Point2d>& positions, bool peak, int window_px) {
  from_.clear();
  to_.clear();
  index_.clear();
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if ((static_cast<int>(i) == peak_) != peak) continue;
    if (!inside(previous_, positions[i]) || !inside(next_, advected_[i])) continue;
    from_.emplace_back(static_cast<float>(positions[i].x), static_cast<float>(positions[i].y));
    to_.emplace_back(static_cast<float>(advected_[i].x), static_cast<float>(advected_[i].y));
    index_.push_back(i);
  }
  if (from_.empty()) return;
  const int w = window_px;
  cv::calcOpticalFlowPyrLK(previous_, next_, from_, to_, lk_status_, lk_error_, cv::Size(w, w), 0,
                           cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.001),
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  for (std::size_t k = 0; k < index_.size(); ++k) {
    const cv::Point2d refined(static_cast<double>(to_[k].x), static_cast<double>(to_[k].y));
    const cv::Point2d d = refined - advected_[index_[k]];
    if (lk_status_[k] != 0 && std::isfinite(d.x) && std::isfinite(d.y) && std::hypot(d.x, d.y) <= 0.5 * w) {
      advected_[index_[k]] = refined;
    }
  }
}

void FlowAdvector::commit(const std::vector<cv::Point2d>& positions, const std::vector<std::uint8_t>& refresh) {
  CV_Assert(positions.size() == templates_.size() && refresh.size() == templates_.size());
  for (std::size_t i = 0; i < templates_.size(); ++i) {
    // A template follows slow changes of appearance (deformation) but not a sudden one (an
    // occluder partly over the patch), which would teach it the occluder.
    const bool similar = i < last_similarity_.size() && last_similarity_[i] >= config_.refresh_similarity;
    if (refresh[i] != 0 && similar && inside(next_, positions[i])) {
      extract_patch(next_, positions[i], config_.patch_px, templates_[i]);
    }
  }
  std::swap(previous_, next_);
}

}  // namespace pliant::vision::webcam
