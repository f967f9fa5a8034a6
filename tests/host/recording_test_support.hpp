// Shared helpers for the recording tests: scratch directories and error-message checks.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "pliant/host/recording.hpp"
#include "../support/temp_dir.hpp"

namespace pliant::host::test {

/// A scratch directory (tests/support/temp_dir.hpp) that can also write files into itself.
class TempDir : public test_support::TempDir {
 public:
  TempDir() : test_support::TempDir("pliant-recording-test-") {}

  std::string str() const { return path().string(); }

  /// Writes `text` to `relative` (parent directories created) and returns its full path.
  std::filesystem::path write(const std::string& relative, const std::string& text) const {
    const std::filesystem::path file = path() / relative;
    std::filesystem::create_directories(file.parent_path());
    std::ofstream out(file, std::ios::binary);
    out << text;
    return file;
  }
};

/// Runs `action` and returns the RecordingError message it throws, "<no error>" when it
/// returns normally, or "<other exception: ...>" for any other exception type.
template <typename Action>
std::string error_of(Action&& action) {
  try {
    action();
  } catch (const RecordingError& error) {
    return error.what();
  } catch (const std::exception& error) {
    return std::string("<other exception: ") + error.what() + ">";
  }
  return "<no error>";
}

/// Checks the one-line message format: starts with `prefix` (file and line, or file and key)
/// and contains `cause`.
inline void expect_message(const std::string& message, const std::string& prefix, const std::string& cause) {
  EXPECT_EQ(message.rfind(prefix, 0), 0u) << "message: " << message << "\nexpected prefix: " << prefix;
  EXPECT_NE(message.find(cause), std::string::npos) << "message: " << message << "\nexpected cause: " << cause;
  EXPECT_EQ(message.find('\n'), std::string::npos) << "message spans lines: " << message;
}

/// Names parameterized cases by their `name` member.
struct CaseName {
  template <typename Param>
  std::string operator()(const ::testing::TestParamInfo<Param>& param) const {
    return param.param.name;
  }
};

/// A valid 2D recording.json for 4 particles with only particles.csv.
inline const char* const kMinimalJson2D = R"({
  "format": "pliant-recording",
  "version": 1,
  "dimension": 2,
  "length_unit": "m",
  "particles": { "count": 4 },
  "files": { "particles": "particles.csv" }
})";

/// Two complete frames of the 4 particles of kMinimalJson2D.
inline const char* const kParticles2D =
    "t,id,x,y\n"
    "0,0,0,0\n0,1,1,0\n0,2,0,1\n0,3,1,1\n"
    "0.5,0,0,0\n0.5,1,1.1,0\n0.5,2,0,1\n0.5,3,1.1,1\n";

}  // namespace pliant::host::test
