#include "record_media.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "atomic_write.hpp"
#include "cli_registry.hpp"

namespace pliant::cli {
namespace {

namespace fs = std::filesystem;

constexpr const char* kColorVideo = "color.avi";
constexpr const char* kColorFrames = "color_frames.csv";
constexpr const char* kDepthFrames = "depth_frames.csv";
constexpr const char* kDepthDirectory = "depth";
// The container rate is estimated from the first frames: this many, or this span.
constexpr std::size_t kRateFrames = 10;
constexpr double kRateSpan_s = 0.5;
constexpr double kFallbackFps = 30.0;

struct Job {
  bool depth = false;
  cv::Mat image;  // colour: CV_8UC1 (mono8) or CV_8UC3 (rgb8 / bgr8); depth: CV_16UC1
  hal::PixelFormat format = hal::PixelFormat::bgr8;
  double t_s = 0;
  double depth_scale_m = 0, fx = 0, fy = 0, cx = 0, cy = 0;
  std::size_t bytes() const { return image.total() * image.elemSize(); }
};

// Shortest text that reads back to the same double; "nan" for a missing value.
std::string number(double value) {
  if (!std::isfinite(value)) return "nan";
  char text[40];
  const std::to_chars_result end = std::to_chars(text, text + sizeof text, value);
  return std::string(text, end.ptr);
}

cv::Mat to_bgr(const Job& job) {
  if (job.format == hal::PixelFormat::bgr8) return job.image;
  cv::Mat bgr;
  cv::cvtColor(job.image, bgr, job.format == hal::PixelFormat::mono8 ? cv::COLOR_GRAY2BGR : cv::COLOR_RGB2BGR);
  return bgr;
}

// Median of the positive intervals between consecutive stamps; the fallback without any.
double estimate_fps(const std::deque<Job>& frames) {
  std::vector<double> intervals;
  for (std::size_t i = 1; i < frames.size(); ++i) {
    const double dt = frames[i].t_s - frames[i - 1].t_s;
    if (dt > 0) intervals.push_back(dt);
  }
  if (intervals.empty()) return kFallbackFps;
  std::nth_element(intervals.begin(), intervals.begin() + static_cast<std::ptrdiff_t>(intervals.size() / 2),
                   intervals.end());
  const double fps = 1.0 / intervals[intervals.size() / 2];
  return std::clamp(std::round(fps * 1000.0) / 1000.0, 0.1, 1000.0);
}

}  // namespace

struct MediaWriter::Impl {
  std::string directory;
  std::size_t max_queued_bytes;

  mutable std::mutex mutex;
  std::condition_variable wake;
  std::deque<Job> queue;
  std::size_t queued_bytes = 0;
  bool finishing = false;
  std::string error;
  std::thread thread;

  // Encoder-thread state (read by the loop thread only after the join in finish()).
  std::deque<Job> pending;  // colour frames held until the container rate is known
  cv::VideoWriter video;
  cv::Size color_size;
  double color_fps = 0;
  std::vector<double> color_times;
  std::uint64_t size_mismatches = 0;
  std::vector<DepthFrameRow> depth_rows;
  bool depth_directory_made = false;

  Impl(std::string dir, std::size_t max_bytes) : directory(std::move(dir)), max_queued_bytes(max_bytes) {
    thread = std::thread([this] { run(); });
  }

  ~Impl() {
    {
      std::lock_guard<std::mutex> lock(mutex);
      finishing = true;
      queue.clear();
    }
    wake.notify_all();
    if (thread.joinable()) thread.join();
  }

  bool push(Job job) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (!error.empty() || finishing) return false;
      if (queued_bytes + job.bytes() > max_queued_bytes) return false;
      queued_bytes += job.bytes();
      queue.push_back(std::move(job));
    }
    wake.notify_one();
    return true;
  }

  void run() {
    for (;;) {
      Job job;
      {
        std::unique_lock<std::mutex> lock(mutex);
        wake.wait(lock, [this] { return finishing || !queue.empty(); });
        if (queue.empty()) return;  // finishing and drained
        job = std::move(queue.front());
        queue.pop_front();
        queued_bytes -= job.bytes();
        if (!error.empty()) continue;  // after an error, queued frames are discarded
      }
      try {
        if (job.depth) {
          write_depth(job);
        } else {
          write_color(std::move(job));
        }
      } catch (const std::exception& e) {
        set_error(e.what());
      }
    }
  }

  void set_error(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex);
    if (error.empty()) error = what;
    for (char& c : error) {
      if (c == '\n' || c == '\r') c = ' ';
    }
  }

  void write_color(Job job) {
    if (color_size.empty()) color_size = job.image.size();
    if (job.image.size() != color_size) {
      ++size_mismatches;
      return;
    }
    if (video.isOpened()) {
      append_color(job);
      return;
    }
    pending.push_back(std::move(job));
    if (pending.size() >= kRateFrames ||
        (pending.size() >= 3 && pending.back().t_s - pending.front().t_s >= kRateSpan_s)) {
      open_video_and_flush();
    }
  }

  void open_video_and_flush() {
    color_fps = estimate_fps(pending);
    const std::string path = (fs::path(directory) / kColorVideo).string();
    if (!video.open(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), color_fps, color_size, true)) {
      throw std::runtime_error(std::string(kColorVideo) + ": OpenCV cannot open a Motion-JPEG writer");
    }
    for (const Job& job : pending) append_color(job);
    pending.clear();
  }

  void append_color(const Job& job) {
    video.write(to_bgr(job));
    color_times.push_back(job.t_s);
  }

  void write_depth(const Job& job) {
    if (!depth_directory_made) {
      std::error_code ec;
      fs::create_directories(fs::path(directory) / kDepthDirectory, ec);
      if (ec) throw std::runtime_error(std::string(kDepthDirectory) + ": cannot create: " + ec.message());
      depth_directory_made = true;
    }
    DepthFrameRow row;
    row.index = static_cast<int>(depth_rows.size());
    char name[32];
    std::snprintf(name, sizeof name, "%s/%06d.png", kDepthDirectory, row.index);
    row.file = name;
    const std::string path = (fs::path(directory) / row.file).string();
    if (!cv::imwrite(path, job.image)) throw std::runtime_error(row.file + ": cannot write the PNG");
    row.t_s = job.t_s;
    row.depth_scale_m = job.depth_scale_m;
    row.fx = job.fx;
    row.fy = job.fy;
    row.cx = job.cx;
    row.cy = job.cy;
    depth_rows.push_back(std::move(row));
  }

  void finish() {
    {
      std::lock_guard<std::mutex> lock(mutex);
      finishing = true;
    }
    wake.notify_all();
    if (thread.joinable()) thread.join();
    if (!error.empty()) throw std::runtime_error(error);
    try {
      if (!pending.empty()) open_video_and_flush();
      if (video.isOpened()) video.release();
    } catch (const std::exception& e) {
      throw std::runtime_error(single(e.what()));
    }
    if (!color_times.empty()) {
      std::error_code ec;
      const auto bytes = fs::file_size(fs::path(directory) / kColorVideo, ec);
      if (ec || bytes == 0) throw std::runtime_error(std::string(kColorVideo) + ": OpenCV wrote nothing");
      std::ostringstream csv;
      csv << "index,t\n";
      for (std::size_t i = 0; i < color_times.size(); ++i) csv << i << ',' << number(color_times[i]) << '\n';
      write_file_atomically((fs::path(directory) / kColorFrames).string(), csv.str());
    }
    if (!depth_rows.empty()) {
      std::ostringstream csv;
      csv << "index,t,file,depth_scale_m,fx,fy,cx,cy\n";
      for (const DepthFrameRow& r : depth_rows) {
        csv << r.index << ',' << number(r.t_s) << ',' << r.file << ',' << number(r.depth_scale_m) << ',' << number(r.fx)
            << ',' << number(r.fy) << ',' << number(r.cx) << ',' << number(r.cy) << '\n';
      }
      write_file_atomically((fs::path(directory) / kDepthFrames).string(), csv.str());
    }
  }

  static std::string single(std::string text) {
    for (char& c : text) {
      if (c == '\n' || c == '\r') c = ' ';
    }
    return text;
  }
};

MediaWriter::MediaWriter(std::string directory, std::size_t max_queued_bytes)
    : impl_(std::make_unique<Impl>(std::move(directory), max_queued_bytes)) {}

MediaWriter::~MediaWriter() = default;

bool MediaWriter::push_color(const hal::ColorFrame& frame, double t_s) {
  if (frame.data == nullptr || frame.width <= 0 || frame.height <= 0 ||
      frame.stride_bytes < frame.width * hal::pixel_bytes(frame.format)) {
    return false;
  }
  Job job;
  job.format = frame.format;
  job.t_s = t_s;
  const int type = frame.format == hal::PixelFormat::mono8 ? CV_8UC1 : CV_8UC3;
  // A header over the HAL buffer (not written through), copied at once.
  const cv::Mat view(frame.height, frame.width, type, const_cast<std::uint8_t*>(frame.data),
                     static_cast<std::size_t>(frame.stride_bytes));
  job.image = view.clone();
  return impl_->push(std::move(job));
}

bool MediaWriter::push_depth(const hal::DepthFrame& frame, double t_s) {
  if (frame.data == nullptr || frame.width <= 0 || frame.height <= 0 || frame.stride_bytes < 2 * frame.width) {
    return false;
  }
  Job job;
  job.depth = true;
  job.t_s = t_s;
  job.depth_scale_m = frame.depth_scale_m;
  job.fx = frame.fx;
  job.fy = frame.fy;
  job.cx = frame.cx;
  job.cy = frame.cy;
  const cv::Mat view(frame.height, frame.width, CV_16UC1, const_cast<std::uint16_t*>(frame.data),
                     static_cast<std::size_t>(frame.stride_bytes));
  job.image = view.clone();
  return impl_->push(std::move(job));
}

std::string MediaWriter::error() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->error;
}

void MediaWriter::finish() { impl_->finish(); }

const std::vector<double>& MediaWriter::color_times() const { return impl_->color_times; }
double MediaWriter::color_fps() const { return impl_->color_fps; }
int MediaWriter::color_width() const { return impl_->color_size.width; }
int MediaWriter::color_height() const { return impl_->color_size.height; }
const std::vector<DepthFrameRow>& MediaWriter::depth_rows() const { return impl_->depth_rows; }
std::uint64_t MediaWriter::size_mismatches() const { return impl_->size_mismatches; }

void register_record_media(CliRegistry& registry) {
  registry.media = [](const std::string& directory) -> std::unique_ptr<MediaSink> {
    return std::make_unique<MediaWriter>(directory);
  };
  registry.quiet_logs.push_back(
      [] { cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR); });  // our one-line messages only
}

}  // namespace pliant::cli
