// The one error type of the webcam front end for input it cannot use.
#pragma once

#include <stdexcept>

namespace pliant::vision::webcam {

/// Input the webcam front end refuses: a video that cannot be opened or decoded, an image that
/// cannot be read, a frame whose size differs from the first, an empty or out-of-frame region,
/// a malformed option value (--roi, --grid, --support, --driven), a mask of the wrong size.
/// what() is exactly one line and names the input (file name, option) and the cause. The
/// command line reports it and exits with status 2. Other failures (I/O while writing, an
/// OpenCV fault) are std::runtime_error.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace pliant::vision::webcam
