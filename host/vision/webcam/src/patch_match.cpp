// Patch extraction, normalised cross-correlation and the small template search used to find a
// particle again after it was hidden.
#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "pliant/vision/webcam_flow.hpp"

namespace pliant::vision::webcam {
namespace {

// Below this grey-level standard deviation a patch has no texture to correlate.
constexpr double kFlatStd = 0.5;
constexpr double kFlatMeanTolerance = 8.0;

// Vertex offset of the parabola through (-1, a), (0, b), (1, c), within [-1/2, 1/2].
double parabola_peak(double a, double b, double c) {
  const double denominator = a - 2 * b + c;
  if (!(denominator < 0)) return 0;
  return std::clamp(0.5 * (a - c) / denominator, -0.5, 0.5);
}

}  // namespace

void extract_patch(const cv::Mat& grey, const cv::Point2d& p, int size_px, cv::Mat& patch) {
  CV_Assert(grey.type() == CV_8UC1 && size_px >= 1 && size_px % 2 == 1);
  cv::getRectSubPix(grey, cv::Size(size_px, size_px), cv::Point2f(static_cast<float>(p.x), static_cast<float>(p.y)),
                    patch, CV_32F);
}

double patch_similarity(const cv::Mat& a, const cv::Mat& b) {
  CV_Assert(a.type() == CV_32FC1 && b.type() == CV_32FC1 && a.size() == b.size() && !a.empty());
  cv::Scalar mean_a, std_a, mean_b, std_b;
  cv::meanStdDev(a, mean_a, std_a);
  cv::meanStdDev(b, mean_b, std_b);
  const bool flat_a = std_a[0] < kFlatStd, flat_b = std_b[0] < kFlatStd;
  if (flat_a || flat_b) return flat_a && flat_b && std::abs(mean_a[0] - mean_b[0]) < kFlatMeanTolerance ? 1.0 : 0.0;
  double sum = 0;
  for (int y = 0; y < a.rows; ++y) {
    const float* pa = a.ptr<float>(y);
    const float* pb = b.ptr<float>(y);
    for (int x = 0; x < a.cols; ++x) {
      sum += (static_cast<double>(pa[x]) - mean_a[0]) * (static_cast<double>(pb[x]) - mean_b[0]);
    }
  }
  const double n = static_cast<double>(a.total());
  return std::clamp(sum / (n * std_a[0] * std_b[0]), -1.0, 1.0);
}

PatchMatch search_patch(const cv::Mat& grey, const cv::Mat& templ, const cv::Point2d& centre, int radius_px) {
  CV_Assert(templ.type() == CV_32FC1 && templ.rows == templ.cols && templ.rows % 2 == 1 && radius_px >= 0);
  PatchMatch best;
  best.position = centre;
  cv::Scalar mean_t, std_t;
  cv::meanStdDev(templ, mean_t, std_t);
  cv::Mat area;
  if (std_t[0] < kFlatStd) {
    // Nothing to search with: judge the patch in place.
    extract_patch(grey, centre, templ.rows, area);
    best.similarity = patch_similarity(templ, area);
    return best;
  }
  extract_patch(grey, centre, templ.rows + 2 * radius_px, area);
  cv::Mat score;
  cv::matchTemplate(area, templ, score, cv::TM_CCOEFF_NORMED);
  cv::patchNaNs(score, -1.0);
  double peak = 0;
  cv::Point at;
  cv::minMaxLoc(score, nullptr, &peak, nullptr, &at);
  double dx = 0, dy = 0;
  if (at.x > 0 && at.x < score.cols - 1) {
    dx = parabola_peak(score.at<float>(at.y, at.x - 1), score.at<float>(at.y, at.x), score.at<float>(at.y, at.x + 1));
  }
  if (at.y > 0 && at.y < score.rows - 1) {
    dy = parabola_peak(score.at<float>(at.y - 1, at.x), score.at<float>(at.y, at.x), score.at<float>(at.y + 1, at.x));
  }
  best.position = centre + cv::Point2d(at.x - radius_px + dx, at.y - radius_px + dy);
  best.similarity = std::clamp(peak, -1.0, 1.0);
  return best;
}

}  // namespace pliant::vision::webcam
