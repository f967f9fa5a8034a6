// Dense flow (OpenCV DIS or Farneback) and its windowed mean at a particle.
#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/video/tracking.hpp>

#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_flow.hpp"

namespace pliant::vision::webcam {

const char* flow_method_name(FlowMethod method) { return method == FlowMethod::dis ? "dis" : "farneback"; }

FlowMethod parse_flow_method(const std::string& name) {
  if (name == "dis") return FlowMethod::dis;
  if (name == "farneback") return FlowMethod::farneback;
  throw InputError("--flow: expected dis or farneback, found '" + name + "'");
}

struct DenseFlow::Impl {
  cv::Ptr<cv::DISOpticalFlow> dis;
};

DenseFlow::DenseFlow(FlowMethod method, int dis_finest_scale) : method_(method), impl_(std::make_unique<Impl>()) {
  if (dis_finest_scale < 0 || dis_finest_scale > 4) throw InputError("DIS finest scale must be 0..4");
  if (method_ == FlowMethod::dis) {
    impl_->dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_FAST);
    impl_->dis->setFinestScale(dis_finest_scale);
  }
}

int dis_finest_scale_for_spacing(double spacing_px) {
  // DIS's patches are 8 px at its finest pyramid level, 8 x 2^s px in the frame: keep them
  // within half the particle spacing so the flow resolves the deformation between particles.
  if (!(spacing_px > 0)) return 0;
  return static_cast<int>(std::clamp(std::floor(std::log2(spacing_px / 16.0)), 0.0, 2.0));
}

DenseFlow::~DenseFlow() = default;

void DenseFlow::compute(const cv::Mat& from, const cv::Mat& to, cv::Mat& flow) {
  CV_Assert(from.type() == CV_8UC1 && to.type() == CV_8UC1 && from.size() == to.size());
  // A fresh output: DIS would otherwise take a same-sized input flow as its initial guess.
  flow.release();
  if (method_ == FlowMethod::dis) {
    impl_->dis->calc(from, to, flow);
  } else {
    cv::calcOpticalFlowFarneback(from, to, flow, 0.5, 3, 15, 3, 5, 1.2, 0);
  }
}

cv::Point2d window_mean_flow(const cv::Mat& flow, const cv::Point2d& p, int window_px) {
  CV_Assert(flow.type() == CV_32FC2 && window_px >= 1 && !flow.empty());
  // The samples share one fractional offset, so their bilinear weights separate: a block of
  // (window_px + 1)^2 pixels with edge weights (1 - f) and f and interior weight 1.
  const double half = 0.5 * (window_px - 1);
  const double sx = p.x - half, sy = p.y - half;
  const double fx0 = std::floor(sx), fy0 = std::floor(sy);
  const double fx = sx - fx0, fy = sy - fy0;
  const int x0 = static_cast<int>(fx0), y0 = static_cast<int>(fy0);
  const int last_x = flow.cols - 1, last_y = flow.rows - 1;
  double sum_x = 0, sum_y = 0;
  for (int j = 0; j <= window_px; ++j) {
    const double wy = j == 0 ? 1 - fy : (j == window_px ? fy : 1.0);
    if (wy == 0) continue;
    const int y = std::clamp(y0 + j, 0, last_y);
    const cv::Vec2f* line = flow.ptr<cv::Vec2f>(y);
    double row_x = 0, row_y = 0;
    for (int i = 0; i <= window_px; ++i) {
      const double wx = i == 0 ? 1 - fx : (i == window_px ? fx : 1.0);
      const cv::Vec2f& v = line[std::clamp(x0 + i, 0, last_x)];
      row_x += wx * static_cast<double>(v[0]);
      row_y += wx * static_cast<double>(v[1]);
    }
    sum_x += wy * row_x;
    sum_y += wy * row_y;
  }
  const double n = static_cast<double>(window_px) * window_px;
  return {sum_x / n, sum_y / n};
}

}  // namespace pliant::vision::webcam
