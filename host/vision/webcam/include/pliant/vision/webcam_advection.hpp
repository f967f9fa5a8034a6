// Particle advection by dense flow with the checks that decide whether a particle was seen.
//
// Per frame pair (previous -> next) and particle i at p (its tracked position in previous):
//   1. advect: q = p + o, o the flow averaged over a window_px x window_px window around p
//      (the MSM paper's eq. 14, bilinear sub-pixel samples);
//   1b. refine: q is refined by pyramid-free Lucas-Kanade (OpenCV calcOpticalFlowPyrLK, started
//      at q) over a refine_window_px window at full resolution. Dense flow is regularised over
//      its patches (DIS: 8 x 2^s px) and so flattens a sharp displacement peak such as the one
//      under a tool, a bias that accumulates frame after frame and pushes msm_beta up; the small
//      LK window follows the peak, and the particle under the tool (set_peak), where the
//      displacement peaks, gets a narrower one still. A refinement that fails (LK status) or
//      moves q by more than half its window keeps the eq. 14 position;
//   2. forward-backward: the backward flow (next -> previous) averaged around q should bring q
//      back to p; e = |q + o_back(q) - p| above fb_threshold_px marks the flow there unreliable
//      (occlusion boundaries, flow errors);
//   3. appearance: the patch_px patch around q in next must look like the particle's template
//      (its patch in the last frame where it was seen): a normalised cross-correlation below
//      min_similarity means something else is there (an occluder passing over it, which the
//      forward-backward check cannot see once both flows follow the occluder);
//   A particle failing 2 or 3 is not observed this frame ("inconsistent", "dissimilar");
//   4. a particle not seen in the previous frame (hidden, failed, or refused by the tracker: its
//      p is then the tracker's estimate) is looked for instead: its template is searched within
//      search_radius_px of q and of the caller's prediction; a match at min_similarity or better
//      is an observation at the matched position ("found"). This is how a particle is picked up
//      again after an occluder has passed.
// The dense flows are computed over the flow region only: the bounding box of the particles'
// positions and predictions grown by flow_margin_px on every side and clipped to the frame (the
// whole frame with flow_margin_px = -1). Flow is local, so inside the margin it matches the whole
// frame's; the cost falls with the region's area (a 4 x 8 grid 100 px apart in a 1920 x 1080
// video: about a fifth of the frame).
// Observations are only candidates: the caller's tracker decides which it uses (commit), and the
// templates of those are retaken from the new frame when the patch still looks like the template
// (refresh_similarity): deformation changes a patch slowly, an occluder sliding over it suddenly.
//
// Units: pixels (webcam_grid.hpp convention). Memory: the flows, two frames and one template per
// particle; allocates at start() and per frame (OpenCV). Not thread-safe.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "pliant/vision/webcam_flow.hpp"

namespace pliant::vision::webcam {

struct AdvectionConfig {
  int window_px = 10;            ///< [1, 101]: eq. 14's averaging window (the paper: 10)
  double fb_threshold_px = 1.0;  ///< > 0: largest forward-backward error of a seen particle
  bool forward_backward = true;  ///< false skips step 2 and the backward flow (half the flow cost)
  double min_similarity = 0.8;   ///< (-1, 1]: least template correlation of an observation
  /// [min_similarity, 1]: a template is retaken (commit) only from a patch at least this
  /// similar to it: it follows deformation, not an occluder sliding over the patch.
  double refresh_similarity = 0.9;
  int patch_px = 11;         ///< odd, [5, 101]: side of the appearance patch
  int search_radius_px = 4;  ///< [0, 50]: reach of the template search (step 4)
  /// DIS pyramid level the flow is resolved at (0..4); -1: dis_finest_scale_for_spacing of the
  /// particle spacing (the tracking pipeline resolves it before constructing the advector).
  int dis_finest_scale = -1;
  /// Side of the Lucas-Kanade window that refines each advected position at full resolution
  /// (step 1b); 0 turns the refinement off (eq. 14 alone). Odd, 3..51 otherwise.
  int refine_window_px = 9;
  /// Side of the refining window for the particle under the tool (set_peak): the displacement
  /// peaks there, and a window averages the peak down by about its curvature times the window's
  /// area, every frame, so the tool's path comes out short and msm_beta high. Odd, 3..51, at
  /// most refine_window_px.
  int peak_refine_window_px = 3;
  /// Pixels the flow region reaches beyond the particles' bounding box: 16..4096, or -1 for the
  /// whole frame. It bounds the motion the flow can follow between two frames and gives the
  /// coarse pyramid levels context; 96 px is three times the largest motion per frame the
  /// rendered presses show.
  int flow_margin_px = 96;
};

/// Throws InputError naming the first field out of range.
void check_advection_config(const AdvectionConfig& config);

enum class ObservationKind : std::uint8_t {
  advected = 0,      ///< passed steps 2 and 3: observed at q
  found = 1,         ///< not seen in the previous frame, its template found by the search
  inconsistent = 2,  ///< forward-backward error above fb_threshold_px
  dissimilar = 3,    ///< the patch at q does not look like the template (an occluder)
  outside = 4,       ///< p or q outside the frame
  not_found = 5,     ///< not seen in the previous frame and the search found nothing
};

const char* observation_kind_name(ObservationKind kind);

struct ParticleObservation {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  cv::Point2d position{kNaN, kNaN};  ///< px in the next frame; NaN unless usable()
  double fb_error_px = kNaN;         ///< step 2's e at q (NaN: not computed)
  double similarity = kNaN;          ///< correlation of the accepted patch or of the best try
  ObservationKind kind = ObservationKind::outside;
  bool usable() const { return kind == ObservationKind::advected || kind == ObservationKind::found; }
};

class FlowAdvector {
 public:
  /// Throws InputError when `config` is out of range; dis_finest_scale -1 means the preset's 2.
  FlowAdvector(FlowMethod method, const AdvectionConfig& config);

  /// First frame (CV_8UC1) and the particles' positions in it: takes their templates.
  void start(const cv::Mat& grey, const std::vector<cv::Point2d>& positions);

  /// Observes the particles in `next` (CV_8UC1, the first frame's size). positions[i]: where the
  /// particle is in the previous frame; predicted[i]: where the caller expects it in `next`
  /// (used by the search); seen[i] != 0 when the particle was observed in the previous frame.
  /// Fills out[i]. All vectors have the particle count given to start().
  void observe(const cv::Mat& next, const std::vector<cv::Point2d>& positions,
               const std::vector<cv::Point2d>& predicted, const std::vector<std::uint8_t>& seen,
               std::vector<ParticleObservation>& out);

  /// The particle at the peak of the displacement (the tool's contact; -1: none), refined with
  /// peak_refine_window_px from the next observe() on.
  void set_peak(int particle) { peak_ = particle; }

  /// Ends the frame: the templates of particles with refresh[i] != 0 are retaken from `next` at
  /// positions[i] (their corrected positions), and `next` becomes the previous frame.
  void commit(const std::vector<cv::Point2d>& positions, const std::vector<std::uint8_t>& refresh);

  /// The last observe()'s flows, over flow_region() (the flow at frame pixel p is at p - its
  /// top-left corner).
  const cv::Mat& forward_flow() const { return forward_; }
  const cv::Mat& backward_flow() const { return backward_; }
  const cv::Rect& flow_region() const { return region_; }
  const AdvectionConfig& config() const { return config_; }

 private:
  void refine(const std::vector<cv::Point2d>& positions);
  void refine_with(const std::vector<cv::Point2d>& positions, bool peak, int window_px);
  PatchMatch search(const cv::Mat& templ, const cv::Point2d& a, const cv::Point2d& b) const;
  /// Mean flow of `flow` (over region_) around frame pixel p (eq. 14's window).
  cv::Point2d mean_flow(const cv::Mat& flow, const cv::Point2d& p) const;

  DenseFlow flow_;
  AdvectionConfig config_;
  cv::Mat previous_, next_, forward_, backward_, patch_;
  cv::Rect region_;                        // the flows' region of the frame
  cv::Mat previous_region_, next_region_;  // the frames over region_, continuous
  std::vector<cv::Mat> templates_;
  std::vector<double> last_similarity_;
  std::vector<cv::Point2d> advected_;   // eq. 14 positions, then refined
  std::vector<cv::Point2f> from_, to_;  // calcOpticalFlowPyrLK's points
  std::vector<std::size_t> index_;      // particle of each LK point
  std::vector<unsigned char> lk_status_;
  int peak_ = -1;
  std::vector<float> lk_error_;
};

}  // namespace pliant::vision::webcam
