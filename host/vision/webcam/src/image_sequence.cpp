// Image sequences: printf-style patterns and globs expanded into file lists, read with imread.
#include <glob.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "image_sequence.hpp"
#include "pliant/vision/webcam_error.hpp"

namespace pliant::vision::webcam {
namespace {

namespace fs = std::filesystem;

// Bounds the files one pattern may expand to (hours of video at 30 Hz), so a pattern over a
// directory of other numbered files cannot make the expansion run away.
constexpr int kMaxSequenceFiles = 1000000;

// The printf integer field of a pattern: '%', optional '0', optional width, 'd'. Returns the
// position of '%' and the length of the field, or npos when there is none. A pattern with two
// fields or an unknown conversion is not a pattern (it may be a plain file name with a '%').
struct IntegerField {
  std::size_t at = std::string::npos;
  std::size_t length = 0;
  int width = 0;
  bool zero_pad = false;
};

IntegerField find_integer_field(const std::string& text) {
  IntegerField field;
  int fields = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') continue;
    std::size_t j = i + 1;
    bool zero = false;
    if (j < text.size() && text[j] == '0') {
      zero = true;
      ++j;
    }
    int width = 0;
    while (j < text.size() && text[j] >= '0' && text[j] <= '9' && width < 100) {
      width = width * 10 + (text[j] - '0');
      ++j;
    }
    if (j < text.size() && text[j] == 'd' && width < 100) {
      ++fields;
      field.at = i;
      field.length = j + 1 - i;
      field.width = width;
      field.zero_pad = zero;
      i = j;
    } else {
      return {};
    }
  }
  return fields == 1 ? field : IntegerField{};
}

std::string format_number(const IntegerField& field, int number) {
  std::string digits = std::to_string(number);
  const std::size_t width = static_cast<std::size_t>(field.width);
  if (digits.size() < width) digits.insert(0, width - digits.size(), field.zero_pad ? '0' : ' ');
  return digits;
}

bool is_regular_file(const std::string& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);
}

std::vector<std::string> expand_printf(const std::string& pattern, const IntegerField& field) {
  const std::string head = pattern.substr(0, field.at);
  const std::string tail = pattern.substr(field.at + field.length);
  const auto name = [&](int number) { return head + format_number(field, number) + tail; };
  int first = 0;
  if (!is_regular_file(name(0))) first = 1;
  if (!is_regular_file(name(first))) {
    throw InputError(pattern + ": no file for number 0 or 1 (" + name(0) + ", " + name(1) + ")");
  }
  std::vector<std::string> files;
  for (int number = first; number - first < kMaxSequenceFiles && is_regular_file(name(number)); ++number) {
    files.push_back(name(number));
  }
  return files;
}

std::vector<std::string> expand_glob(const std::string& pattern) {
  glob_t matches{};
  const int status = glob(pattern.c_str(), 0, nullptr, &matches);
  std::vector<std::string> files;
  if (status == 0) {
    for (std::size_t i = 0; i < matches.gl_pathc && files.size() < static_cast<std::size_t>(kMaxSequenceFiles); ++i) {
      if (is_regular_file(matches.gl_pathv[i])) files.emplace_back(matches.gl_pathv[i]);
    }
  }
  globfree(&matches);
  if (status == GLOB_NOSPACE || status == GLOB_ABORTED) throw InputError(pattern + ": cannot list the matching files");
  if (files.empty()) throw InputError(pattern + ": no file matches");
  // Byte order, whatever the locale: frame_10 after frame_09 needs zero-padded names.
  std::sort(files.begin(), files.end());
  return files;
}

class ImageSequenceSource final : public FrameSource {
 public:
  ImageSequenceSource(std::string name, std::vector<std::string> files, double fps_hz)
      : name_(std::move(name)), files_(std::move(files)), fps_(fps_hz) {}

  bool read(cv::Mat& image, std::string& label) override {
    if (next_ >= files_.size()) return false;
    label = files_[next_++];
    if (!is_regular_file(label)) throw InputError(label + ": no such file (removed while reading?)");
    try {
      image = cv::imread(label, cv::IMREAD_UNCHANGED);
    } catch (const cv::Exception&) {
      image.release();
    }
    if (image.empty()) throw InputError(label + ": cannot read the image (missing, damaged or not an image)");
    return true;
  }
  double fps() const override { return fps_; }
  int frame_count() const override { return static_cast<int>(files_.size()); }
  const std::string& name() const override { return name_; }

 private:
  std::string name_;
  std::vector<std::string> files_;
  double fps_;
  std::size_t next_ = 0;
};

}  // namespace

std::vector<std::string> expand_image_pattern(const std::string& input) {
  const IntegerField field = find_integer_field(input);
  if (field.at != std::string::npos && !is_regular_file(input)) return expand_printf(input, field);
  if (input.find_first_of("*?[") != std::string::npos && !is_regular_file(input)) return expand_glob(input);
  return {};
}

std::unique_ptr<FrameSource> open_image_sequence(const std::string& input, std::vector<std::string> files,
                                                 double fps_hz) {
  return std::make_unique<ImageSequenceSource>(input, std::move(files), fps_hz);
}

}  // namespace pliant::vision::webcam
