// `pliant record`: the particles of a recording made without a tracked video: the gripper's two
// jaws (docs/record.md, "Particles").
//
// Like a compression test that observes only its platens, the object is seen only where the
// tool touches it: 2D, length unit m, two particles on the x axis of the jaw frame,
//   particle 0  jaw A, fixed at (0, 0)            particles.fixed  = [0]
//   particle 1  jaw B, at (width, 0), driven       particles.driven = [1]
// one frame per kept gripper reading (t, width), so the rest configuration is the opening at the
// first reading. The measured wrench, when there is one, is applied to particle 1.
// Host code: allocates and throws.
#pragma once

#include <string>
#include <vector>

#include "pliant/host/recording.hpp"
#include "record_writer.hpp"

namespace pliant::cli {

/// The recording of the jaws over `rows` (strictly increasing t). Throws std::runtime_error
/// when `rows` is empty ("the gripper delivered no reading").
host::Recording jaw_recording(const std::vector<GripperRow>& rows, const std::string& name);

}  // namespace pliant::cli
