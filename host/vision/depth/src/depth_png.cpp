// 16-bit PNG depth frames through libpng's own API: its error and warning callbacks are ours, so a
// corrupt file becomes one DepthError and nothing is printed (libpng's default handlers, which
// OpenCV's decoder leaves in place, write to stderr).
//
// libpng reports errors by longjmp. The functions that setjmp hold only trivially destructible
// locals, and every C++ object they use lives in their callers, so no destructor is skipped.
#include <png.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <vector>

#include "pliant/vision/depth_image.hpp"

namespace pliant::vision {
namespace {

// Larger images are refused before any pixel buffer is allocated (16384 x 16384 is 512 MiB).
constexpr png_uint_32 kMaxSide = 16384;

struct Source {
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  std::size_t offset = 0;
  char message[160] = {};
};

void on_read(png_structp png, png_bytep out, png_size_t count) {
  auto* source = static_cast<Source*>(png_get_io_ptr(png));
  if (count > source->size - source->offset) png_error(png, "file cut short");
  std::memcpy(out, source->data + source->offset, count);
  source->offset += count;
}

[[noreturn]] void on_error(png_structp png, png_const_charp message) {
  auto* source = static_cast<Source*>(png_get_error_ptr(png));
  std::strncpy(source->message, message != nullptr ? message : "unknown error", sizeof source->message - 1);
  png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}  // warnings change nothing we read

struct Header {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int bit_depth = 0;
  int color_type = 0;
  int channels = 0;
};

// Returns false after a libpng error (the message is in the source).
bool read_header(png_structp png, png_infop info, Header* header) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_user_limits(png, kMaxSide, kMaxSide);
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
  // The fuzz target's mutations would almost all stop at a chunk's CRC; skip it to reach the
  // image data. Never in the library itself.
  png_set_crc_action(png, PNG_CRC_QUIET_USE, PNG_CRC_QUIET_USE);
#endif
  png_read_info(png, info);
  header->width = png_get_image_width(png, info);
  header->height = png_get_image_height(png, info);
  header->bit_depth = png_get_bit_depth(png, info);
  header->color_type = png_get_color_type(png, info);
  header->channels = png_get_channels(png, info);
  return true;
}

bool read_pixels(png_structp png, png_infop info, png_bytep* rows) {
  if (setjmp(png_jmpbuf(png))) return false;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
    // PNG stores 16-bit samples big-endian: host order already.
#else
  png_set_swap(png);  // PNG stores 16-bit samples big-endian; we want host order
#endif
  (void)png_set_interlace_handling(png);
  png_read_update_info(png, info);
  png_read_image(png, rows);
  png_read_end(png, nullptr);
  return true;
}

// Owns libpng's read structures.
class PngRead {
 public:
  explicit PngRead(Source& source) {
    png_ = png_create_read_struct(PNG_LIBPNG_VER_STRING, &source, on_error, on_warning);
    if (png_ != nullptr) info_ = png_create_info_struct(png_);
    if (png_ != nullptr) png_set_read_fn(png_, &source, on_read);
  }
  ~PngRead() { png_destroy_read_struct(&png_, info_ != nullptr ? &info_ : nullptr, nullptr); }
  PngRead(const PngRead&) = delete;
  PngRead& operator=(const PngRead&) = delete;
  bool ok() const { return png_ != nullptr && info_ != nullptr; }
  png_structp png() const { return png_; }
  png_infop info() const { return info_; }

 private:
  png_structp png_ = nullptr;
  png_infop info_ = nullptr;
};

}  // namespace

DepthImage decode_depth_png(const std::uint8_t* bytes, std::size_t size, const std::string& label) {
  if (bytes == nullptr || size == 0) throw DepthError(label + ": empty file");
  static const std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size < 8 || !std::equal(kSignature, kSignature + 8, bytes)) throw DepthError(label + ": not a PNG file");
  // IHDR, the first chunk, gives the size: a too large image is named before libpng looks.
  if (size >= 24 && std::memcmp(bytes + 12, "IHDR", 4) == 0) {
    auto big_endian = [&](std::size_t at) {
      return (static_cast<std::uint32_t>(bytes[at]) << 24) | (static_cast<std::uint32_t>(bytes[at + 1]) << 16) |
             (static_cast<std::uint32_t>(bytes[at + 2]) << 8) | static_cast<std::uint32_t>(bytes[at + 3]);
    };
    const std::uint32_t width = big_endian(16), height = big_endian(20);
    if (width > kMaxSide || height > kMaxSide) {
      throw DepthError(label + ": image of " + std::to_string(width) + "x" + std::to_string(height) +
                       " pixels is larger than " + std::to_string(kMaxSide) + " on a side");
    }
  }
  Source source;
  source.data = bytes;
  source.size = size;
  PngRead read(source);
  if (!read.ok()) throw DepthError(label + ": cannot start the PNG decoder");
  Header header;
  if (!read_header(read.png(), read.info(), &header))
    throw DepthError(label + ": corrupt PNG (" + source.message + ")");
  if (header.bit_depth != 16) {
    throw DepthError(label + ": depth PNG must be 16-bit (this one is " + std::to_string(header.bit_depth) + "-bit)");
  }
  if (header.color_type != PNG_COLOR_TYPE_GRAY || header.channels != 1) {
    throw DepthError(label + ": depth PNG must have one channel (this one has " + std::to_string(header.channels) +
                     ")");
  }
  // Deflate expands at most 1032:1, so a file too small for its claimed size is corrupt: refused
  // before the pixel buffer (up to 512 MiB) is allocated for it.
  const double raw_bytes = static_cast<double>(header.height) * (1.0 + 2.0 * static_cast<double>(header.width));
  if (raw_bytes > 1032.0 * static_cast<double>(size) + 1024.0) {
    throw DepthError(label + ": corrupt PNG (" + std::to_string(size) + " bytes cannot hold a " +
                     std::to_string(header.width) + "x" + std::to_string(header.height) + " image)");
  }
  DepthImage image;
  image.width = static_cast<int>(header.width);
  image.height = static_cast<int>(header.height);
  image.data.assign(static_cast<std::size_t>(header.width) * header.height, 0);
  std::vector<png_bytep> rows(header.height);
  for (png_uint_32 v = 0; v < header.height; ++v) {
    rows[v] = reinterpret_cast<png_bytep>(image.data.data() + static_cast<std::size_t>(v) * header.width);
  }
  if (!read_pixels(read.png(), read.info(), rows.data()))
    throw DepthError(label + ": corrupt PNG (" + source.message + ")");
  return image;
}

DepthImage read_depth_png(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DepthError(path + ": cannot open");
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw DepthError(path + ": read error");
  return decode_depth_png(bytes.data(), bytes.size(), path);
}

}  // namespace pliant::vision
