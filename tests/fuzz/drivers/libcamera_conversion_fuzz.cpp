// libFuzzer target over the libcamera driver's handling of camera buffers: the native-format
// conversion (drivers/libcamera/src/pixel_conversion.cpp) and the completion path of the frame
// pipeline (frame_pipeline.cpp: plane assembly from the mapped buffer and bytes-used, sequence
// numbering, triple buffer), fed through a backend whose buffer is the fuzz input.
//
// Input: bytes 0..7 pick the geometry and metadata, the rest is the buffer:
//   0 format (mod 10: the nine formats and one unsupported), 1 output format (mod 4: rgb, bgr,
//   mono, one invalid), 2 width (1..64; odd ones too), 3 height (1..64), 4 stride padding
//   (0..15 bytes; 255: a stride below a row), 5 bit 0 full range, bit 1 BT.709, bit 2 two planes,
//   bit 3 status error, 6..7 bytes used (little-endian; 0: all).
// Checked: no out-of-bounds access (ASan), a successful conversion fills exactly the output rows,
// and the pipeline delivers a frame exactly when the conversion of the same bytes succeeds.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "frame_pipeline.hpp"
#include "pixel_conversion.hpp"

namespace {

using pliant::drivers::LibcameraCameraConfig;
using pliant::hal::HalStatus;
using pliant::hal::PixelFormat;
namespace lc = pliant::drivers::libcamera_detail;

void check(bool condition) {
  if (!condition) std::abort();
}

class FixedClock final : public pliant::hal::Clock {
 public:
  double now_s() const noexcept override { return 100.0; }
};

std::uint64_t fixed_now_ns() noexcept { return 1'000'000'000ull; }

// One buffer: the fuzz input after the header, in one plane or split in two.
class InputBackend final : public lc::CaptureBackend {
 public:
  InputBackend(const std::uint8_t* data, std::size_t size, std::size_t split, bool two_planes)
      : data_(data), size_(size), split_(split), two_planes_(two_planes) {}
  HalStatus open(const LibcameraCameraConfig&, lc::StreamSetup&, std::string&) override { return HalStatus::ok; }
  lc::BufferPlanes buffer(int index) const noexcept override {
    lc::BufferPlanes planes;
    if (index != 0) return planes;
    if (two_planes_) {
      planes.count = 2;
      planes.data[0] = data_;
      planes.length[0] = split_;
      planes.data[1] = data_ + split_;
      planes.length[1] = size_ - split_;
    } else {
      planes.count = 1;
      planes.data[0] = data_;
      planes.length[0] = size_;
    }
    return planes;
  }
  HalStatus start(lc::CompletionSink&, std::string&) override { return HalStatus::ok; }
  bool requeue(int) noexcept override {
    ++requeues;
    return true;
  }
  void stop() noexcept override {}
  void close() noexcept override {}
  int requeues = 0;

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t split_;
  bool two_planes_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 8) return 0;
  static const lc::RawFormat formats[] = {lc::RawFormat::rgb888,     lc::RawFormat::bgr888, lc::RawFormat::xrgb8888,
                                          lc::RawFormat::xbgr8888,   lc::RawFormat::yuyv,   lc::RawFormat::uyvy,
                                          lc::RawFormat::nv12,       lc::RawFormat::nv21,   lc::RawFormat::r8,
                                          lc::RawFormat::unsupported};
  const lc::RawFormat format = formats[data[0] % 10];
  const auto out_format = static_cast<PixelFormat>(data[1] % 4);
  const int width = 1 + data[2] % 64;
  const int height = 1 + data[3] % 64;
  const std::size_t row = lc::raw_row_bytes(format, width);
  const std::size_t stride = data[4] == 255 ? (row > 0 ? row - 1 : 0) : row + data[4] % 16;
  const bool full_range = (data[5] & 1) != 0;
  const bool bt709 = (data[5] & 2) != 0;
  const bool two_planes = (data[5] & 4) != 0;
  const bool error_status = (data[5] & 8) != 0;
  const std::size_t bytes_used = static_cast<std::size_t>(data[6]) | static_cast<std::size_t>(data[7]) << 8;
  // A heap copy of the buffer, so ASan sees its exact end.
  const std::vector<std::uint8_t> buffer(data + 8, data + size);
  const std::size_t luma_bytes = stride * static_cast<std::size_t>(height);
  const std::size_t split = luma_bytes < buffer.size() ? luma_bytes : buffer.size();

  // The conversion alone, on the same planes the pipeline will assemble.
  lc::RawImage image;
  image.format = format;
  image.width = width;
  image.height = height;
  image.matrix = bt709 ? lc::YcbcrMatrix::bt709 : lc::YcbcrMatrix::bt601;
  image.full_range = full_range;
  image.stride[0] = image.stride[1] = stride;
  const std::size_t used0 = bytes_used > 0 && bytes_used < (two_planes ? split : buffer.size())
                                ? bytes_used
                                : (two_planes ? split : buffer.size());
  image.plane[0] = buffer.data();
  image.plane_bytes[0] = used0;
  bool assembled = true;
  if (lc::raw_format_planes(format) == 2) {
    if (two_planes) {
      image.plane[1] = buffer.data() + split;
      image.plane_bytes[1] = buffer.size() - split;
    } else if (used0 >= luma_bytes) {
      image.plane[1] = buffer.data() + luma_bytes;
      image.plane_bytes[1] = used0 - luma_bytes;
      image.plane_bytes[0] = luma_bytes;
    } else {
      assembled = false;
    }
  }
  const std::size_t pixel = out_format == PixelFormat::mono8 ? 1 : 3;
  const std::size_t out_stride = static_cast<std::size_t>(width) * pixel + 5;
  std::vector<std::uint8_t> out(out_stride * static_cast<std::size_t>(height), 0xA5);
  const lc::ConvertStatus status = assembled ? lc::convert_raw(image, out_format, out.data(), out_stride, out.size())
                                             : lc::ConvertStatus::short_buffer;
  if (status == lc::ConvertStatus::ok) {
    for (int y = 0; y < height; ++y) {  // the padding after each row is never written
      for (std::size_t k = static_cast<std::size_t>(width) * pixel; k < out_stride; ++k) {
        check(out[static_cast<std::size_t>(y) * out_stride + k] == 0xA5);
      }
    }
  }

  // The pipeline on the same buffer (only with a valid output format and a supported input:
  // the camera refuses other configurations before a pipeline exists).
  if (format == lc::RawFormat::unsupported || static_cast<int>(out_format) > 2) return 0;
  InputBackend backend(buffer.data(), buffer.size(), split, two_planes);
  lc::StreamSetup setup;
  setup.format = format;
  setup.width = width;
  setup.height = height;
  setup.stride = stride;
  setup.buffer_count = 1;
  setup.matrix = image.matrix;
  setup.full_range = full_range;
  lc::FramePipeline pipeline(setup, out_format, backend, &fixed_now_ns);
  pipeline.begin();
  lc::Completion completion;
  completion.buffer = 0;
  completion.status = error_status ? lc::CompletionStatus::error : lc::CompletionStatus::success;
  completion.sequence = data[6];
  completion.timestamp_ns = 999'000'000ull;
  completion.bytes_used[0] = bytes_used;
  pipeline.on_completion(completion);
  check(backend.requeues == 1);
  FixedClock clock;
  pliant::hal::ColorFrame frame;
  const HalStatus taken = pipeline.take(frame, clock);
  const bool expect_frame = !error_status && status == lc::ConvertStatus::ok;
  check((taken == HalStatus::ok) == expect_frame);
  if (expect_frame) {
    check(frame.width == width && frame.height == height && frame.header.sequence == 1);
    check(std::fabs(frame.header.stamp_s - (100.0 - 0.001)) < 1e-9);
    for (int y = 0; y < height; ++y) {
      check(std::memcmp(frame.data + static_cast<std::size_t>(y) * static_cast<std::size_t>(frame.stride_bytes),
                        out.data() + static_cast<std::size_t>(y) * out_stride,
                        static_cast<std::size_t>(width) * pixel) == 0);
    }
  }
  pipeline.end();
  return 0;
}
