#include "record_output.hpp"

#include <sys/stat.h>  // mkdir

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <system_error>

#include "exit_status.hpp"

namespace pliant::cli {
namespace {

namespace fs = std::filesystem;

// The target without trailing separators ("rec/" -> "rec").
fs::path normal_target(const std::string& target) {
  fs::path path(target);
  while (!path.has_filename() && path.has_parent_path() && path != path.root_path()) path = path.parent_path();
  return path;
}

// Creates "<base><suffix>XXXXXX" (six random letters or digits) beside base with mkdir, so that
// the directory gets the usual permissions (0777 less the umask; mkdtemp would give 0700).
std::string make_unique_directory(const fs::path& base, const char* suffix) {
  static const char letters[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
  std::random_device entropy;
  std::mt19937 random(entropy());
  std::uniform_int_distribution<std::size_t> pick(0, sizeof letters - 2);
  int err = 0;
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string path = base.string() + suffix;
    for (int i = 0; i < 6; ++i) path += letters[pick(random)];
    if (::mkdir(path.c_str(), 0777) == 0) return path;
    err = errno;
    if (err != EEXIST) break;
  }
  throw std::runtime_error("cannot create a directory beside " + base.string() + ": " + std::strerror(err));
}

bool replaceable(const fs::path& target) {
  std::error_code ec;
  if (fs::is_symlink(fs::symlink_status(target, ec))) return false;
  if (!fs::is_directory(target, ec)) return false;
  if (fs::is_regular_file(target / "recording.json", ec)) return true;
  return fs::is_empty(target, ec) && !ec;
}

}  // namespace

OutputDirectory::OutputDirectory(const std::string& target, bool force) : force_(force) {
  if (target.empty()) throw UsageError("-o: empty output name");
  const fs::path path = normal_target(target);
  if (!path.has_filename() || path.filename() == "." || path.filename() == "..") {
    throw UsageError("-o '" + target + "': name a new directory");
  }
  shown_ = path.string();
  std::error_code ec;
  target_ = fs::absolute(path, ec).lexically_normal().string();
  if (ec) throw std::runtime_error("-o '" + target + "': " + ec.message());
  if (!target_.empty() && target_.back() == '/') target_.pop_back();
  const fs::file_status status = fs::symlink_status(path, ec);
  if (fs::exists(status)) {
    if (!force) throw UsageError(shown_ + " exists; give --force to replace it");
    if (!replaceable(path)) {
      throw UsageError(shown_ +
                       " exists and is not a recording (no recording.json) nor an empty directory; "
                       "not replacing it, even with --force");
    }
  }
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (!fs::is_directory(parent, ec)) throw UsageError("-o '" + target + "': no such directory " + parent.string());
  partial_ = make_unique_directory(fs::path(target_), ".partial-");
}

OutputDirectory::~OutputDirectory() {
  if (committed_ || partial_.empty()) return;
  std::error_code ec;
  fs::remove_all(partial_, ec);  // best effort: nothing else can be done in a destructor
}

std::string OutputDirectory::name() const { return fs::path(shown_).filename().string(); }

void OutputDirectory::commit() {
  const fs::path target(target_);
  std::error_code ec;
  std::string old;
  if (force_ && fs::exists(fs::symlink_status(target, ec))) {
    if (!replaceable(target)) throw std::runtime_error(shown_ + " changed during the recording; not replacing it");
    old = make_unique_directory(target, ".old-");
    fs::rename(target, old, ec);  // onto the new empty directory
    if (ec) {
      const std::string cause = ec.message();
      fs::remove(old, ec);
      throw std::runtime_error("cannot move the old " + shown_ + " aside: " + cause);
    }
  }
  fs::rename(partial_, target, ec);
  if (ec) {
    const std::string cause = ec.message();
    if (!old.empty()) fs::rename(old, target, ec);
    throw std::runtime_error("cannot rename the recording to " + shown_ + ": " + cause);
  }
  committed_ = true;
  if (!old.empty()) fs::remove_all(old, ec);
}

}  // namespace pliant::cli
