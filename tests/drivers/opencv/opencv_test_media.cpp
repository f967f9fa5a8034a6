#include "opencv_test_media.hpp"

#include <chrono>
#include <cstdlib>
#include <thread>
#include <fstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

namespace pliant::drivers::opencv_test {

cv::Vec3b frame_bgr(int k) {
  return cv::Vec3b(static_cast<unsigned char>(10 + 30 * k), static_cast<unsigned char>(220 - 25 * k),
                   static_cast<unsigned char>(60 + 17 * k));
}

cv::Mat make_frame(int k, int width, int height) { return cv::Mat(height, width, CV_8UC3, cv::Scalar(frame_bgr(k))); }

void write_video(const std::string& path, int count, double fps, int width, int height) {
  cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps, cv::Size(width, height));
  if (!writer.isOpened()) throw std::runtime_error("cannot write " + path);
  for (int k = 0; k < count; ++k) writer.write(make_frame(k, width, height));
}

void write_png(const std::string& path, int k, int width, int height) {
  if (!cv::imwrite(path, make_frame(k, width, height))) throw std::runtime_error("cannot write " + path);
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream file(path, std::ios::binary);
  file << bytes;
  if (!file) throw std::runtime_error("cannot write " + path);
}

int frame_index_of(const cv::Vec3b& bgr, int count, int tolerance) {
  for (int k = 0; k < count; ++k) {
    const cv::Vec3b want = frame_bgr(k);
    bool near = true;
    for (int c = 0; c < 3; ++c) near = near && std::abs(int{want[c]} - int{bgr[c]}) <= tolerance;
    if (near) return k;
  }
  return -1;
}

namespace {

class FakeSource final : public opencv_detail::FrameSource {
 public:
  explicit FakeSource(std::shared_ptr<FakeScript> script) : script_(std::move(script)) {}
  opencv_detail::SourceStatus next(cv::Mat& image, double& media_s) override {
    const int call = script_->calls.fetch_add(1) + 1;
    if (dead_) return opencv_detail::SourceStatus::disconnected;
    if (script_->throw_next.exchange(false)) throw std::runtime_error("fake backend failure");
    if (script_->fail_next.exchange(false)) {
      dead_ = true;
      return opencv_detail::SourceStatus::disconnected;
    }
    int permits = script_->permits.load();
    do {
      if (permits <= 0) {
        if (script_->on_idle) script_->on_idle();
        return opencv_detail::SourceStatus::idle;
      }
    } while (!script_->permits.compare_exchange_weak(permits, permits - 1));
    const int number = script_->yielded.load();
    image.create(script_->height.load(), script_->width.load(), CV_8UC3);
    image.setTo(cv::Scalar::all(number % 256));
    media_s = number * 0.1;
    script_->last_yield_call.store(call);
    script_->yielded.fetch_add(1);
    return opencv_detail::SourceStatus::frame;
  }

 private:
  std::shared_ptr<FakeScript> script_;
  bool dead_ = false;
};

}  // namespace

bool wait_settled(const FakeScript& script, int yielded) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < deadline) {
    // last_yield_call is stored before yielded is incremented: once the count is reached, a
    // later call means the camera finished with the last frame.
    if (script.yielded.load() >= yielded && script.calls.load() > script.last_yield_call.load()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

bool emit_and_settle(FakeScript& script, int frames) {
  const int target = script.yielded.load() + frames;
  script.permits += frames;
  return wait_settled(script, target);
}

std::unique_ptr<opencv_detail::FrameSource> FakeFactory::open(opencv_detail::OpenError& error) {
  script_->opens.fetch_add(1);
  if (script_->failing_opens.load() > 0) {
    script_->failing_opens.fetch_sub(1);
    error.status = hal::HalStatus::disconnected;
    error.message = "fake device absent";
    return nullptr;
  }
  return std::make_unique<FakeSource>(script_);
}

}  // namespace pliant::drivers::opencv_test
