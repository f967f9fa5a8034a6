// drivers/libcamera internal: the CaptureBackend over libcamera 0.0.3, and the process-wide
// CameraManager it shares (libcamera allows one per process).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "capture_backend.hpp"

namespace pliant::drivers::libcamera_detail {

std::unique_ptr<CaptureBackend> make_libcamera_backend();

/// Ids of the cameras libcamera lists; `error` set when the manager would not start.
std::vector<std::string> libcamera_camera_ids(std::string& error);

}  // namespace pliant::drivers::libcamera_detail
