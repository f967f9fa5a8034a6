// Dense optical flow between two grey frames, its windowed mean at a particle (the MSM paper's
// eq. 14) and the appearance checks on small patches.
//
// Units: flow in pixels from the first frame to the second, positions in pixels (webcam_grid.hpp
// convention). Host code: allocates, OpenCV may throw cv::Exception on internal faults.
// Thread safety: a DenseFlow object is used by one thread at a time; the free functions are
// reentrant.
#pragma once

#include <memory>
#include <string>

#include <opencv2/core.hpp>

namespace pliant::vision::webcam {

enum class FlowMethod {
  dis,        ///< DIS (Kroeger et al. 2016), OpenCV's "fast" preset: the default, fast
  farneback,  ///< Farneback polynomial expansion, as the MSM paper used (OpenCV parameters below)
};

/// "dis" / "farneback" and back; parse throws InputError on anything else.
const char* flow_method_name(FlowMethod method);
FlowMethod parse_flow_method(const std::string& name);

/// One flow algorithm with its settings. DIS: OpenCV's PRESET_FAST (8 px patches every 4 px,
/// 16 gradient-descent iterations, 5 variational refinement iterations) computed down to
/// pyramid level `dis_finest_scale` (the preset's is 2: flow resolved on a quarter-size image).
/// Farneback: pyramid scale 0.5, 3 levels, 15 px window, 3 iterations, poly_n 5, poly_sigma 1.2.
class DenseFlow {
 public:
  /// Throws InputError unless dis_finest_scale is 0..4.
  explicit DenseFlow(FlowMethod method, int dis_finest_scale = 2);
  ~DenseFlow();
  DenseFlow(const DenseFlow&) = delete;
  DenseFlow& operator=(const DenseFlow&) = delete;

  /// Flow from `from` to `to` (both CV_8UC1, same size) into `flow` (CV_32FC2, same size):
  /// the point at p in `from` is at p + flow(p) in `to`. No state is carried between calls.
  void compute(const cv::Mat& from, const cv::Mat& to, cv::Mat& flow);
  FlowMethod method() const { return method_; }

 private:
  FlowMethod method_;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The DIS finest scale for particles `spacing_px` apart: the largest s in 0..2 whose patch
/// footprint 8 x 2^s px is at most half the spacing (100 px: 2, the preset's; 30 px: 0).
int dis_finest_scale_for_spacing(double spacing_px);

/// Mean flow over a window_px x window_px window centred at `p` (eq. 14: the flow averaged over
/// a 10 x 10 region): window_px^2 samples at p + (i - (window_px - 1) / 2, j - (window_px - 1) / 2),
/// each interpolated bilinearly, so the mean moves smoothly with sub-pixel p. Samples beyond
/// the frame take the nearest edge value. `flow` CV_32FC2; window_px >= 1; p finite.
/// O(window_px^2).
cv::Point2d window_mean_flow(const cv::Mat& flow, const cv::Point2d& p, int window_px);

/// Square patch of `size_px` (odd) centred at sub-pixel `p` in `grey` (CV_8UC1), bilinear,
/// edges replicated, as CV_32FC1 in `patch`.
void extract_patch(const cv::Mat& grey, const cv::Point2d& p, int size_px, cv::Mat& patch);

/// Normalised cross-correlation of two CV_32FC1 patches of one size, in [-1, 1]: 1 is the same
/// appearance up to brightness and contrast. Two flat patches (no texture) give 1 when their
/// means agree within 8 grey levels, else 0; one flat and one textured give 0.
double patch_similarity(const cv::Mat& a, const cv::Mat& b);

/// Best match of `templ` (CV_32FC1, odd size) within `radius_px` pixels of `centre` in `grey`:
/// the sub-pixel position (parabolic peak interpolation) and its normalised cross-correlation.
struct PatchMatch {
  cv::Point2d position;
  double similarity = -1;
};
PatchMatch search_patch(const cv::Mat& grey, const cv::Mat& templ, const cv::Point2d& centre, int radius_px);

}  // namespace pliant::vision::webcam
