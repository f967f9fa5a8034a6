// drivers/opencv internal: the OpenCV-backed source factories, one per source kind.
#pragma once

#include <memory>
#include <string>

#include "frame_source.hpp"

namespace pliant::drivers::opencv_detail {

/// Frame rate that stamps files which carry none, when the config gives none either, Hz.
inline constexpr double kDefaultFps = 30.0;

/// The index of a location made of 1..4 decimal digits ("0", "12"), else -1 (a path).
int device_index(const std::string& location) noexcept;

std::shared_ptr<SourceFactory> make_video_file_factory(const OpenCvCameraConfig& config);
std::shared_ptr<SourceFactory> make_device_factory(const OpenCvCameraConfig& config);
std::shared_ptr<SourceFactory> make_sequence_factory(const OpenCvCameraConfig& config);

}  // namespace pliant::drivers::opencv_detail
