// Naming of image sequences: patterns parsed by hand, natural order, image extensions. Pure
// functions (the fuzz target compiles this file alone).
#include "pliant/drivers/opencv/image_files.hpp"

#include <cctype>
#include <cstddef>

namespace pliant::drivers::opencv_files {

namespace {

bool is_digit(char c) noexcept { return c >= '0' && c <= '9'; }

char lower(char c) noexcept { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

}  // namespace

bool parse_sequence_pattern(std::string_view pattern, SequencePattern& out, std::string& error) {
  SequencePattern parsed;
  std::string* text = &parsed.prefix;
  int conversions = 0;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    const char c = pattern[i];
    if (c != '%') {
      text->push_back(c);
      continue;
    }
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      text->push_back('%');
      ++i;
      continue;
    }
    // A conversion: [0][width](d|i|u).
    std::size_t j = i + 1;
    bool zero = false;
    if (j < pattern.size() && pattern[j] == '0') {
      zero = true;
      ++j;
    }
    int width = 0;
    int digits = 0;
    while (j < pattern.size() && is_digit(pattern[j])) {
      if (++digits > 2) {
        error = "image pattern: field width of more than 2 digits";
        return false;
      }
      width = width * 10 + (pattern[j] - '0');
      ++j;
    }
    if (j >= pattern.size() || (pattern[j] != 'd' && pattern[j] != 'i' && pattern[j] != 'u')) {
      error = "image pattern: only %d, %Nd and %0Nd conversions (and %%) are allowed";
      return false;
    }
    if (width > 20) {
      error = "image pattern: field width above 20";
      return false;
    }
    if (++conversions > 1) {
      error = "image pattern: more than one conversion";
      return false;
    }
    parsed.width = width;
    parsed.zero_pad = zero && width > 0;
    text = &parsed.suffix;
    i = j;
  }
  if (conversions == 0) {
    error = "image pattern: no %d conversion (and not a directory or a glob)";
    return false;
  }
  out = std::move(parsed);
  return true;
}

std::string sequence_name(const SequencePattern& pattern, std::uint64_t index) {
  char digits[24];
  int n = 0;
  do {
    digits[n++] = static_cast<char>('0' + index % 10);
    index /= 10;
  } while (index != 0);
  std::string name = pattern.prefix;
  for (int pad = pattern.width - n; pad > 0; --pad) name.push_back(pattern.zero_pad ? '0' : ' ');
  while (n > 0) name.push_back(digits[--n]);
  name += pattern.suffix;
  return name;
}

bool natural_less(std::string_view a, std::string_view b) noexcept {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (is_digit(a[i]) && is_digit(b[j])) {
      // Compare the digit runs by value: skip leading zeros, then the longer run is larger,
      // then digit by digit; equal values: the shorter run (fewer leading zeros) first.
      std::size_t ia = i, jb = j;
      while (ia < a.size() && a[ia] == '0') ++ia;
      while (jb < b.size() && b[jb] == '0') ++jb;
      std::size_t ea = ia, eb = jb;
      while (ea < a.size() && is_digit(a[ea])) ++ea;
      while (eb < b.size() && is_digit(b[eb])) ++eb;
      const std::size_t la = ea - ia, lb = eb - jb;
      if (la != lb) return la < lb;
      for (std::size_t k = 0; k < la; ++k) {
        if (a[ia + k] != b[jb + k]) return a[ia + k] < b[jb + k];
      }
      const std::size_t run_a = ea - i, run_b = eb - j;
      if (run_a != run_b) return run_a < run_b;
      i = ea;
      j = eb;
      continue;
    }
    if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
    ++i;
    ++j;
  }
  return (a.size() - i) < (b.size() - j);
}

bool has_image_extension(std::string_view name) noexcept {
  static constexpr std::string_view kExtensions[] = {"png", "jpg", "jpeg", "bmp",  "tif", "tiff", "pbm",
                                                     "pgm", "ppm", "pnm",  "webp", "exr", "hdr"};
  const std::size_t dot = name.rfind('.');
  if (dot == std::string_view::npos || dot + 1 >= name.size()) return false;
  const std::string_view ext = name.substr(dot + 1);
  for (const std::string_view candidate : kExtensions) {
    if (candidate.size() != ext.size()) continue;
    bool same = true;
    for (std::size_t k = 0; k < ext.size(); ++k) same = same && lower(ext[k]) == candidate[k];
    if (same) return true;
  }
  return false;
}

bool has_glob_characters(std::string_view name) noexcept { return name.find_first_of("*?[") != std::string_view::npos; }

}  // namespace pliant::drivers::opencv_files
