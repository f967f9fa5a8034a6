// pliant drivers/openni2: its device factories in a hal::DeviceRegistry (hal/device_registry.hpp).
//
// Depth cameras (Openni2Camera, docs/drivers/openni2.md):
//   openni2:any       the first PrimeSense-family camera OpenNI2 enumerates (its current depth mode)
//   openni2:URI       the device with this OpenNI2 URI
//   oni:FILE          an .oni recording, played on the caller's clock as the camera delivered it
//                     (playback real_time) or one frame per read (stepped)
// Parameters: playback real_time | stepped (oni only; default real_time)
// Files are opened by absolute path (OpenNI2's initialisation changes the working directory).
// Errors: the camera's configure status and last_error(). The opened device's info(): size and
// Openni2CameraStats; ended() is end_of_stream().
// Host code (allocates, throws on a duplicate registration).
#pragma once

#include "pliant/hal/device_registry.hpp"

namespace pliant::drivers {

/// Registers openni2 and oni.
void register_openni2_devices(hal::DeviceRegistry& registry);

}  // namespace pliant::drivers
