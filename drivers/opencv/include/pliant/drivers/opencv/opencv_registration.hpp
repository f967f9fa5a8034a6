// pliant drivers/opencv: its device factories in a hal::DeviceRegistry (hal/device_registry.hpp).
//
// Colour cameras (OpenCvCamera, docs/drivers/opencv.md):
//   v4l2:LOCATION     a V4L2 webcam: "/dev/videoN", any /dev path, or an index "N"
//   video:FILE        a video file            } played on the caller's clock as a camera would
//   images:PATTERN    an image sequence       } deliver it (playback real_time), or stepped
// Parameters: format  rgb8 | bgr8 | mono8 (default bgr8, what OpenCV's writers take)
//             playback real_time | stepped (video and images; default real_time)
// Fixed: 8 frames buffered. Files are opened by absolute path (a library that changes the working
// directory must not change what they name). Errors: the camera's configure status and
// last_error(). The opened device's info(): source, size and OpenCvCameraStats; ended() is
// end_of_stream().
// Host code (allocates, throws on a duplicate registration).
#pragma once

#include "pliant/hal/device_registry.hpp"

namespace pliant::drivers {

/// Registers v4l2, video and images.
void register_opencv_devices(hal::DeviceRegistry& registry);

}  // namespace pliant::drivers
