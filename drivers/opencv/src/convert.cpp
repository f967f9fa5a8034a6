#include "convert.hpp"

#include <cstddef>

#include <opencv2/imgproc.hpp>

namespace pliant::drivers::opencv_detail {

namespace {

// The cvtColor code from `channels` (1, 3, 4) to `format`; -1 for a plain copy.
int conversion_code(int channels, hal::PixelFormat format) noexcept {
  switch (format) {
    case hal::PixelFormat::mono8: return channels == 1 ? -1 : channels == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY;
    case hal::PixelFormat::bgr8: return channels == 1 ? cv::COLOR_GRAY2BGR : channels == 3 ? -1 : cv::COLOR_BGRA2BGR;
    case hal::PixelFormat::rgb8:
      return channels == 1 ? cv::COLOR_GRAY2RGB : channels == 3 ? cv::COLOR_BGR2RGB : cv::COLOR_BGRA2RGB;
  }
  return -1;
}

}  // namespace

bool convert_into(const cv::Mat& image, hal::PixelFormat format, std::uint8_t* dst, int stride, cv::Mat& scratch) {
  if (image.empty() || image.dims != 2) return false;
  const int channels = image.channels();
  if (channels != 1 && channels != 3 && channels != 4) return false;
  const cv::Mat* source = &image;
  if (image.depth() == CV_16U) {
    image.convertTo(scratch, CV_8U, 1.0 / 256.0);
    source = &scratch;
  } else if (image.depth() != CV_8U) {
    return false;
  }
  const int type = format == hal::PixelFormat::mono8 ? CV_8UC1 : CV_8UC3;
  cv::Mat out(source->rows, source->cols, type, dst, static_cast<std::size_t>(stride));
  const int code = conversion_code(channels, format);
  if (code < 0) {
    source->copyTo(out);
  } else {
    cv::cvtColor(*source, out, code);
  }
  // The output header wraps the slot; OpenCV keeps it as long as size and type match. A
  // reallocation would mean the slot was never written.
  return out.data == dst;
}

}  // namespace pliant::drivers::opencv_detail
