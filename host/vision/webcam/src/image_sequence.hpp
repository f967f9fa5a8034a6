// Internal: the image-sequence source behind open_frame_source.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pliant/vision/webcam_frames.hpp"

namespace pliant::vision::webcam {

/// `files` non-empty (from expand_image_pattern), fps_hz > 0.
std::unique_ptr<FrameSource> open_image_sequence(const std::string& input, std::vector<std::string> files,
                                                 double fps_hz);

}  // namespace pliant::vision::webcam
