// libFuzzer target over the OpenCV driver's image-sequence naming (drivers/opencv/src/
// image_sequence.cpp): the printf-style pattern parser (a user's pattern, never handed to
// snprintf), the file names it makes, the natural order of names and the extension check.
//
// Input: byte 0 splits the rest into a pattern and a second name (at byte 0 mod the length);
// bytes 1..8 of the rest, little-endian, also give an index.
// Checked: no out-of-bounds access (ASan) or undefined behaviour (UBSan); a parsed pattern names
// files that start with its prefix, end with its suffix and hold the index in decimal with the
// padding asked for; natural_less is irreflexive and asymmetric, and agrees with the order of
// the names a pattern makes for increasing indices.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "pliant/drivers/opencv/image_files.hpp"

namespace {

namespace oc = pliant::drivers::opencv_files;

void check(bool condition) {
  if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string_view rest(reinterpret_cast<const char*>(data + 1), size - 1);
  const std::size_t cut = rest.empty() ? 0 : data[0] % (rest.size() + 1);
  const std::string_view pattern_text = rest.substr(0, cut);
  const std::string_view other = rest.substr(cut);
  std::uint64_t index = 0;
  for (std::size_t i = 0; i < 8 && i < rest.size(); ++i)
    index |= static_cast<std::uint64_t>(static_cast<unsigned char>(rest[i])) << (8 * i);

  oc::SequencePattern pattern;
  std::string error;
  if (oc::parse_sequence_pattern(pattern_text, pattern, error)) {
    check(pattern.width >= 0 && pattern.width <= 20);
    const std::string name = oc::sequence_name(pattern, index);
    check(name.size() >= pattern.prefix.size() + pattern.suffix.size() + 1);
    check(name.compare(0, pattern.prefix.size(), pattern.prefix) == 0);
    check(name.compare(name.size() - pattern.suffix.size(), pattern.suffix.size(), pattern.suffix) == 0);
    const std::string digits =
        name.substr(pattern.prefix.size(), name.size() - pattern.prefix.size() - pattern.suffix.size());
    const std::string plain = std::to_string(index);
    check(digits.size() == (plain.size() > static_cast<std::size_t>(pattern.width)
                                ? plain.size()
                                : static_cast<std::size_t>(pattern.width)));
    check(digits.compare(digits.size() - plain.size(), plain.size(), plain) == 0);
    for (std::size_t k = 0; k + plain.size() < digits.size(); ++k) check(digits[k] == (pattern.zero_pad ? '0' : ' '));
    // Zero-padded names of increasing indices sort naturally in index order (space padding
    // does not: a space sorts before digits byte-wise, as intended for plain text).
    if (pattern.zero_pad && index < UINT64_MAX) {
      const std::string next = oc::sequence_name(pattern, index + 1);
      check(oc::natural_less(name, next));
      check(!oc::natural_less(next, name));
    }
  } else {
    check(!error.empty());
  }
  check(!oc::natural_less(pattern_text, pattern_text));
  check(!(oc::natural_less(pattern_text, other) && oc::natural_less(other, pattern_text)));
  if (pattern_text != other) check(oc::natural_less(pattern_text, other) || oc::natural_less(other, pattern_text));
  (void)oc::has_image_extension(other);
  return 0;
}
