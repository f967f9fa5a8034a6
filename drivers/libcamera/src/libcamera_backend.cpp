// libcamera 0.0.3 (Debian 12): CameraManager, Camera, FrameBufferAllocator and Request, as
// declared in /usr/include/libcamera (the API changed in later versions: e.g. the configuration's
// `transform` became `orientation`, and Camera::generateConfiguration takes a Span).
#include "libcamera_backend.hpp"

#include <sys/mman.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>
#include <utility>

#include <libcamera/libcamera.h>

namespace pliant::drivers::libcamera_detail {

namespace {

using hal::HalStatus;

std::string errno_text(int negative_errno) { return std::strerror(-negative_errno); }

// The process's CameraManager: started on first use, stopped and destroyed with its last user.
struct ManagerHolder {
  std::mutex mutex;
  std::weak_ptr<libcamera::CameraManager> manager;
};

ManagerHolder& holder() {
  static ManagerHolder instance;
  return instance;
}

std::shared_ptr<libcamera::CameraManager> shared_manager(std::string& error) {
  ManagerHolder& h = holder();
  std::lock_guard<std::mutex> lock(h.mutex);
  if (std::shared_ptr<libcamera::CameraManager> existing = h.manager.lock()) return existing;
  auto fresh = std::make_unique<libcamera::CameraManager>();
  const int started = fresh->start();
  if (started < 0) {
    error = "libcamera CameraManager::start failed: " + errno_text(started);
    return nullptr;
  }
  std::shared_ptr<libcamera::CameraManager> manager(fresh.release(), [](libcamera::CameraManager* m) {
    m->stop();
    delete m;
  });
  h.manager = manager;
  return manager;
}

libcamera::StreamRole stream_role(LibcameraRole role) {
  switch (role) {
    case LibcameraRole::viewfinder: return libcamera::StreamRole::Viewfinder;
    case LibcameraRole::still_capture: return libcamera::StreamRole::StillCapture;
    case LibcameraRole::video_recording: break;
  }
  return libcamera::StreamRole::VideoRecording;
}

RawFormat raw_format_of(const libcamera::PixelFormat& format) {
  return format.modifier() == 0 ? raw_format_from_fourcc(format.fourcc()) : RawFormat::unsupported;
}

// The formats this driver converts, best first (no conversion, then cheap ones).
constexpr RawFormat kPreference[] = {RawFormat::rgb888,   RawFormat::bgr888, RawFormat::xrgb8888,
                                     RawFormat::xbgr8888, RawFormat::yuyv,   RawFormat::uyvy,
                                     RawFormat::nv12,     RawFormat::nv21,   RawFormat::r8};

class LibcameraBackend final : public CaptureBackend {
 public:
  LibcameraBackend() = default;
  ~LibcameraBackend() override {
    stop();
    close();
  }

  HalStatus open(const LibcameraCameraConfig& config, StreamSetup& setup, std::string& error) override {
    close();
    const HalStatus status = open_camera(config, setup, error);
    if (status != HalStatus::ok) close();
    return status;
  }

  BufferPlanes buffer(int index) const noexcept override {
    if (index < 0 || static_cast<std::size_t>(index) >= planes_.size()) return {};
    return planes_[static_cast<std::size_t>(index)];
  }

  HalStatus start(CompletionSink& sink, std::string& error) override {
    sink_ = &sink;
    running_ = true;
    const int started = camera_->start();
    if (started < 0) {
      running_ = false;
      error = "libcamera Camera::start failed: " + errno_text(started);
      return HalStatus::io_error;
    }
    for (const std::unique_ptr<libcamera::Request>& request : requests_) {
      request->reuse(libcamera::Request::ReuseBuffers);
      const int queued = camera_->queueRequest(request.get());
      if (queued < 0) {
        error = "libcamera Camera::queueRequest failed: " + errno_text(queued);
        stop();
        return HalStatus::io_error;
      }
    }
    return HalStatus::ok;
  }

  bool requeue(int index) noexcept override {
    if (!running_ || index < 0 || static_cast<std::size_t>(index) >= requests_.size()) return false;
    try {
      libcamera::Request* request = requests_[static_cast<std::size_t>(index)].get();
      request->reuse(libcamera::Request::ReuseBuffers);
      return camera_->queueRequest(request) >= 0;
    } catch (...) {
      return false;
    }
  }

  void stop() noexcept override {
    if (!running_) return;
    running_ = false;
    // Completes every queued request (cancelled) before returning.
    if (camera_) (void)camera_->stop();
  }

  void close() noexcept override {
    if (camera_) {
      camera_->requestCompleted.disconnect(this);
      camera_->disconnected.disconnect(this);
    }
    requests_.clear();
    planes_.clear();
    for (const Mapping& m : mappings_) ::munmap(m.address, m.length);
    mappings_.clear();
    if (allocator_ && stream_ != nullptr) (void)allocator_->free(stream_);
    allocator_.reset();
    stream_ = nullptr;
    configuration_.reset();
    if (camera_ && acquired_) (void)camera_->release();
    acquired_ = false;
    camera_.reset();
    manager_.reset();  // last: cameras are released before the manager goes
    sink_ = nullptr;
  }

 private:
  struct Mapping {
    void* address;
    std::size_t length;
  };

  HalStatus open_camera(const LibcameraCameraConfig& config, StreamSetup& setup, std::string& error) {
    manager_ = shared_manager(error);
    if (!manager_) return HalStatus::io_error;
    const std::vector<std::shared_ptr<libcamera::Camera>> cameras = manager_->cameras();
    if (cameras.empty()) {
      error = "no camera: libcamera lists none";
      return HalStatus::disconnected;
    }
    camera_ = config.camera_id.empty() ? cameras.front() : manager_->get(config.camera_id);
    if (!camera_) {
      error = "no camera with id \"" + config.camera_id + "\" (libcamera lists:";
      for (const auto& c : cameras) error += " \"" + c->id() + "\"";
      error += ")";
      return HalStatus::disconnected;
    }
    const int acquired = camera_->acquire();
    if (acquired < 0) {
      error = "camera " + camera_->id() + " cannot be acquired (" + errno_text(acquired) + "; in use?)";
      return HalStatus::io_error;
    }
    acquired_ = true;

    configuration_ = camera_->generateConfiguration({stream_role(config.role)});
    if (!configuration_ || configuration_->empty()) {
      error = "camera " + camera_->id() + " has no stream for the requested role";
      return HalStatus::unsupported;
    }
    libcamera::StreamConfiguration& stream = configuration_->at(0);
    if (raw_format_of(stream.pixelFormat) == RawFormat::unsupported) {
      const std::vector<libcamera::PixelFormat> offered = stream.formats().pixelformats();
      for (const RawFormat wanted : kPreference) {
        bool found = false;
        for (const libcamera::PixelFormat& f : offered) found = found || raw_format_of(f) == wanted;
        if (found) {
          stream.pixelFormat = libcamera::PixelFormat(raw_format_fourcc(wanted));
          break;
        }
      }
    }
    if (config.width > 0 && config.height > 0) {
      stream.size = libcamera::Size(static_cast<unsigned>(config.width), static_cast<unsigned>(config.height));
    }
    stream.bufferCount = static_cast<unsigned>(config.buffer_count);
    if (configuration_->validate() == libcamera::CameraConfiguration::Invalid) {
      error = "libcamera rejected the stream configuration " + stream.toString();
      return HalStatus::invalid_argument;
    }
    const RawFormat format = raw_format_of(stream.pixelFormat);
    if (format == RawFormat::unsupported) {
      error = "camera " + camera_->id() + " offers no format this driver converts (it has:";
      for (const libcamera::PixelFormat& f : stream.formats().pixelformats()) error += " " + f.toString();
      error += "; converted: RGB888 BGR888 XRGB8888 XBGR8888 YUYV UYVY NV12 NV21 R8; MJPEG is not decoded)";
      return HalStatus::unsupported;
    }
    const int configured = camera_->configure(configuration_.get());
    if (configured < 0) {
      error = "libcamera Camera::configure failed: " + errno_text(configured);
      return HalStatus::io_error;
    }

    stream_ = stream.stream();
    allocator_ = std::make_unique<libcamera::FrameBufferAllocator>(camera_);
    const int allocated = allocator_->allocate(stream_);
    if (allocated <= 0) {
      error = "libcamera FrameBufferAllocator::allocate failed: " + errno_text(allocated < 0 ? allocated : -ENOMEM);
      return HalStatus::io_error;
    }
    const std::vector<std::unique_ptr<libcamera::FrameBuffer>>& buffers = allocator_->buffers(stream_);
    for (std::size_t i = 0; i < buffers.size(); ++i) {
      BufferPlanes planes;
      if (!map_buffer(*buffers[i], planes, error)) return HalStatus::io_error;
      planes_.push_back(planes);
      std::unique_ptr<libcamera::Request> request = camera_->createRequest(i);
      if (!request || request->addBuffer(stream_, buffers[i].get()) < 0) {
        error = "libcamera cannot make a request for buffer " + std::to_string(i);
        return HalStatus::io_error;
      }
      requests_.push_back(std::move(request));
    }
    camera_->requestCompleted.connect(this, &LibcameraBackend::request_completed);
    camera_->disconnected.connect(this, &LibcameraBackend::camera_disconnected);

    setup.format = format;
    setup.width = static_cast<int>(stream.size.width);
    setup.height = static_cast<int>(stream.size.height);
    setup.stride = stream.stride;
    setup.buffer_count = static_cast<int>(buffers.size());
    setup.matrix = YcbcrMatrix::bt601;
    setup.full_range = false;
    if (stream.colorSpace) {
      setup.matrix = stream.colorSpace->ycbcrEncoding == libcamera::ColorSpace::YcbcrEncoding::Rec709
                         ? YcbcrMatrix::bt709
                         : YcbcrMatrix::bt601;
      setup.full_range = stream.colorSpace->range == libcamera::ColorSpace::Range::Full;
    }
    setup.description = camera_->id() + " " + stream.toString();
    return HalStatus::ok;
  }

  // Maps each plane of a buffer read-only. Planes sharing a dmabuf are mapped once, from offset
  // 0 (plane offsets need not be page aligned) up to the end of the last plane in it.
  bool map_buffer(const libcamera::FrameBuffer& buffer, BufferPlanes& planes, std::string& error) {
    const std::vector<libcamera::FrameBuffer::Plane>& list = buffer.planes();
    if (list.empty() || list.size() > 2) {
      error = "unexpected plane count " + std::to_string(list.size());
      return false;
    }
    std::map<int, std::size_t> extent;
    for (const libcamera::FrameBuffer::Plane& p : list) {
      if (p.offset == libcamera::FrameBuffer::Plane::kInvalidOffset) {
        error = "buffer plane without an offset";
        return false;
      }
      std::size_t& end = extent[p.fd.get()];
      end = std::max(end, static_cast<std::size_t>(p.offset) + p.length);
    }
    std::map<int, const std::uint8_t*> base;
    for (const auto& [fd, length] : extent) {
      void* address = ::mmap(nullptr, length, PROT_READ, MAP_SHARED, fd, 0);
      if (address == MAP_FAILED) {
        error = std::string("mmap of a frame buffer failed: ") + std::strerror(errno);
        return false;
      }
      mappings_.push_back({address, length});
      base[fd] = static_cast<const std::uint8_t*>(address);
    }
    planes.count = static_cast<int>(list.size());
    for (std::size_t i = 0; i < list.size(); ++i) {
      planes.data[i] = base[list[i].fd.get()] + list[i].offset;
      planes.length[i] = list[i].length;
    }
    return true;
  }

  // libcamera's thread.
  void request_completed(libcamera::Request* request) {
    if (sink_ == nullptr || request == nullptr) return;
    Completion c;
    c.buffer = static_cast<int>(request->cookie());
    const libcamera::FrameBuffer* buffer = request->findBuffer(stream_);
    if (request->status() == libcamera::Request::RequestCancelled || buffer == nullptr) {
      c.status = CompletionStatus::cancelled;
    } else {
      const libcamera::FrameMetadata& metadata = buffer->metadata();
      c.status = metadata.status == libcamera::FrameMetadata::FrameSuccess     ? CompletionStatus::success
                 : metadata.status == libcamera::FrameMetadata::FrameCancelled ? CompletionStatus::cancelled
                                                                               : CompletionStatus::error;
      c.sequence = metadata.sequence;
      c.timestamp_ns = metadata.timestamp;
      const auto used = metadata.planes();
      for (std::size_t i = 0; i < used.size() && i < 2; ++i) c.bytes_used[i] = used[i].bytesused;
    }
    sink_->on_completion(c);
  }

  void camera_disconnected() {
    if (sink_ != nullptr) sink_->on_disconnected();
  }

  std::shared_ptr<libcamera::CameraManager> manager_;
  std::shared_ptr<libcamera::Camera> camera_;
  bool acquired_ = false;
  std::unique_ptr<libcamera::CameraConfiguration> configuration_;
  libcamera::Stream* stream_ = nullptr;
  std::unique_ptr<libcamera::FrameBufferAllocator> allocator_;
  std::vector<std::unique_ptr<libcamera::Request>> requests_;
  std::vector<Mapping> mappings_;
  std::vector<BufferPlanes> planes_;
  CompletionSink* sink_ = nullptr;
  std::atomic<bool> running_{false};
};

}  // namespace

std::unique_ptr<CaptureBackend> make_libcamera_backend() { return std::make_unique<LibcameraBackend>(); }

std::vector<std::string> libcamera_camera_ids(std::string& error) {
  std::vector<std::string> ids;
  const std::shared_ptr<libcamera::CameraManager> manager = shared_manager(error);
  if (!manager) return ids;
  for (const std::shared_ptr<libcamera::Camera>& camera : manager->cameras()) ids.push_back(camera->id());
  return ids;
}

}  // namespace pliant::drivers::libcamera_detail
