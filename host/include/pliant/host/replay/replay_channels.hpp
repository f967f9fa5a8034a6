// Recording-v1 data as HAL replay channels (pliant/hal/mock/replay_cursor.hpp), so that the
// replay devices can play a recording back through the same interfaces as live devices.
//
//   particles  width particle_count * dimension, one sample per frame, NaN where unobserved,
//              in the recording's length_unit (m or px) and frame
//   wrench     width 6 (fx fy fz tx ty tz), N and N m; absent when the recording has no wrench.csv
//   gripper    width 2 (opening in length_unit, force in N); absent without gripper.csv
// Wrench and gripper rows with equal or decreasing times (the reader accepts them, the replay
// cannot: a device cannot deliver two samples at one instant) are skipped and counted.
// Host code: allocates.
#pragma once

#include <optional>

#include "pliant/hal/mock/replay_cursor.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

struct ReplayChannels {
  hal::RecordedChannel particles;
  std::optional<hal::RecordedChannel> wrench;
  std::optional<hal::RecordedChannel> gripper;
  int skipped_rows = 0;  ///< wrench and gripper rows not after their predecessor
};

ReplayChannels replay_channels_of(const Recording& recording);

}  // namespace pliant::host
