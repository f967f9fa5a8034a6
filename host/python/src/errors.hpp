// Python exceptions for the command line's errors, and warnings for its warning lines.
//
//   pliant.PliantError(RuntimeError)         any failure of the work (the command line's exit 1)
//   pliant.UsageError(PliantError, ValueError)  an option that cannot work (exit 2)
//   pliant.InputError(PliantError, ValueError)  a file the readers reject, naming file and line (exit 2)
//   pliant.PliantWarning(UserWarning)        the command line's "pliant: warning:" lines
// The message is the command line's, without its "pliant COMMAND: " prefix. Wrong Python
// arguments (shapes, dtypes, types) are plain ValueError and TypeError.
#pragma once

#include <string>
#include <vector>

#include "bindings.hpp"

namespace pliant::python {

/// Issues each line as a pliant.PliantWarning (needs the GIL; raises if warnings are errors).
void emit_warnings(const std::vector<std::string>& lines);

}  // namespace pliant::python
