#include "telemetry_outputs.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "exit_status.hpp"

namespace pliant::cli {

namespace fs = std::filesystem;

JsonLinesOutput::JsonLinesOutput(const std::string& path, bool flush_each) : flush_each_(flush_each) {
  if (path.empty() || path == "-") {
    file_ = stdout;
    label_ = "standard output";
    return;
  }
  std::error_code error;
  if (fs::is_directory(path, error)) throw UsageError("-o " + path + " is a directory");
  path_ = path;
  label_ = path;
  // Same directory as the target, so the final rename cannot cross file systems.
  temp_ = path + ".tmp-" + std::to_string(getpid());
  file_ = std::fopen(temp_.c_str(), "wb");
  if (file_ == nullptr) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
}

JsonLinesOutput::~JsonLinesOutput() {
  if (file_ == nullptr || file_ == stdout) return;
  std::fclose(file_);
  std::remove(temp_.c_str());
}

void JsonLinesOutput::write(const std::string& line) {
  const bool ok = std::fwrite(line.data(), 1, line.size(), file_) == line.size() && std::fputc('\n', file_) != EOF &&
                  (!flush_each_ || std::fflush(file_) == 0);
  if (!ok) throw std::runtime_error("cannot write " + label_ + ": " + std::strerror(errno));
}

void JsonLinesOutput::commit() {
  if (file_ == stdout) {
    if (std::fflush(stdout) != 0) throw std::runtime_error("cannot write to standard output");
    return;
  }
  std::FILE* const file = file_;
  file_ = nullptr;
  const bool written = std::fflush(file) == 0 && fsync(fileno(file)) == 0;
  const int write_error = errno;
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed || std::rename(temp_.c_str(), path_.c_str()) != 0) {
    const int error = !written ? write_error : errno;
    std::remove(temp_.c_str());
    throw std::runtime_error("cannot write " + path_ + ": " + std::strerror(error));
  }
}

void check_new_recording_directory(const std::string& directory) {
  std::error_code error;
  const fs::file_status status = fs::status(directory, error);
  if (!fs::exists(status)) return;
  if (!fs::is_directory(status)) throw UsageError(directory + " exists and is not a directory");
  const bool empty = fs::is_empty(directory, error);
  if (error) throw std::runtime_error("cannot read " + directory + ": " + error.message());
  if (!empty) throw UsageError(directory + " is not empty; give a new directory for the recording");
}

void write_recording_atomically(const host::Recording& recording, const std::string& directory) {
  fs::path target = fs::path(directory).lexically_normal();
  if (!target.has_filename()) target = target.parent_path();  // "rec/" -> "rec"
  std::error_code error;
  if (target.has_parent_path()) {
    fs::create_directories(target.parent_path(), error);
    if (error) throw std::runtime_error("cannot create " + target.parent_path().string() + ": " + error.message());
  }
  fs::path temp = target;
  temp += ".pliant-tmp-" + std::to_string(getpid());
  fs::remove_all(temp, error);
  try {
    host::write_recording(recording, temp.string());
  } catch (...) {
    fs::remove_all(temp, error);
    throw;
  }
  fs::rename(temp, target, error);
  if (error) {
    throw std::runtime_error("cannot move the recording into " + directory + ": " + error.message() +
                             "; it is complete in " + temp.string());
  }
}

}  // namespace pliant::cli
