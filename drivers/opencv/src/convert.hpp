// drivers/opencv internal: a decoded OpenCV image into a HAL frame slot.
#pragma once

#include <cstdint>

#include <opencv2/core/mat.hpp>

#include "pliant/hal/camera.hpp"

namespace pliant::drivers::opencv_detail {

/// Converts `image` (OpenCV channel order: gray, BGR or BGRA; 8 or 16 bits per channel, 16-bit
/// scaled by 1/256) into `format` at `dst`, whose rows are `stride` bytes apart and whose size is
/// the image's. false when the image type is not one of those (nothing written). May allocate
/// (`scratch` for 16-bit input, OpenCV's internals); the decoder thread calls it.
bool convert_into(const cv::Mat& image, hal::PixelFormat format, std::uint8_t* dst, int stride, cv::Mat& scratch);

}  // namespace pliant::drivers::opencv_detail
