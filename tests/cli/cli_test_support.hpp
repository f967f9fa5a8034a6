// Helpers for tests that run the `pliant` binary: command runner, temporary directories and a
// tiny valid recording to break in controlled ways.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"

namespace pliant::cli_test {

namespace fs = std::filesystem;

/// Temporary directories named pliant_cli_*.
class TempDir : public test_support::TempDir {
 public:
  TempDir() : test_support::TempDir("pliant_cli_") {}
};

inline std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

/// Single-quoted for /bin/sh.
inline std::string quoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

struct CommandResult {
  int status = -1;  ///< exit status; -1 when the process did not exit normally (crash, signal)
  std::string out;
  std::string err;
  std::vector<std::string> err_lines() const { return lines_of(err); }
};

/// Runs `pliant <arguments>` (already shell-quoted) with stdout and stderr captured.
inline CommandResult run_pliant(const std::string& arguments) {
  TempDir capture;
  const std::string out_path = capture / "stdout";
  const std::string err_path = capture / "stderr";
  const std::string command =
      quoted(PLIANT_EXE) + " " + arguments + " </dev/null >" + quoted(out_path) + " 2>" + quoted(err_path);
  const int raw = std::system(command.c_str());
  CommandResult result;
  result.status = raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  result.out = read_text(out_path);
  result.err = read_text(err_path);
  return result;
}

/// A valid 2D recording: 4 particles (0 and 1 fixed), 3 frames. particles.csv line numbers:
/// 1 header, 2-5 frame t=0, 6-9 frame t=0.1, 10-13 frame t=0.2.
inline const char* tiny_recording_json() {
  return R"({
  "format": "pliant-recording",
  "version": 1,
  "dimension": 2,
  "length_unit": "m",
  "particles": { "count": 4, "fixed": [0, 1] },
  "files": { "particles": "particles.csv" }
}
)";
}

inline const char* tiny_particles_csv() {
  return "t,id,x,y\n"
         "0,0,0,0\n0,1,1,0\n0,2,0,1\n0,3,1,1\n"
         "0.1,0,0,0\n0.1,1,1,0\n0.1,2,0,0.9\n0.1,3,1,0.9\n"
         "0.2,0,0,0\n0.2,1,1,0\n0.2,2,0,0.85\n0.2,3,1,0.85\n";
}

inline void write_tiny_recording(const fs::path& directory) {
  fs::create_directories(directory);
  write_text(directory / "recording.json", tiny_recording_json());
  write_text(directory / "particles.csv", tiny_particles_csv());
}

/// Replaces the first occurrence of `from` (which must occur) in a file.
inline void replace_in_file(const fs::path& path, const std::string& from, const std::string& to) {
  std::string text = read_text(path);
  const std::size_t at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("'" + from + "' not in " + path.string());
  text.replace(at, from.size(), to);
  write_text(path, text);
}

/// Replaces line `number` (1-based) of a file.
inline void replace_line(const fs::path& path, int number, const std::string& line) {
  std::vector<std::string> lines = lines_of(read_text(path));
  if (number < 1 || number > static_cast<int>(lines.size())) throw std::runtime_error("no such line");
  lines[static_cast<std::size_t>(number - 1)] = line;
  std::string text;
  for (const std::string& l : lines) text += l + "\n";
  write_text(path, text);
}

}  // namespace pliant::cli_test
