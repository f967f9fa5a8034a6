// pliant drivers/libcamera: its device factory in a hal::DeviceRegistry (hal/device_registry.hpp).
//
// Colour camera (LibcameraCamera, docs/drivers/libcamera.md):
//   libcamera:any     the first camera libcamera lists
//   libcamera:ID      the camera with this libcamera id
// Parameters: format  rgb8 | bgr8 | mono8 (default bgr8)
// Fixed: the pipeline's default size for video recording. Errors: the camera's configure status
// and last_error(). The opened device's info(): the stream and LibcameraCameraStats.
// Host code (allocates, throws on a duplicate registration).
#pragma once

#include "pliant/hal/device_registry.hpp"

namespace pliant::drivers {

/// Registers libcamera.
void register_libcamera_devices(hal::DeviceRegistry& registry);

}  // namespace pliant::drivers
