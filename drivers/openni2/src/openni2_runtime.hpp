// drivers/openni2 internal: OpenNI2's process-wide initialisation and its device events.
#pragma once

#include <OpenNI.h>

#include <atomic>
#include <string>

namespace pliant::drivers::openni2::detail {

/// OpenNI::initialize() once per process; thread-safe. On failure `error` holds OpenNI2's
/// message and where it looked for drivers; the next call tries again.
bool ensure_openni2(std::string& error);

/// Listens for the end of a recording and for the disconnect of one device (by URI). The
/// callbacks come from OpenNI2's threads and only set flags.
class DeviceEvents final : public openni::OpenNI::DeviceStateChangedListener,
                           public openni::OpenNI::DeviceDisconnectedListener {
 public:
  explicit DeviceEvents(std::string uri) : uri_(std::move(uri)) {}
  ~DeviceEvents() override { detach(); }
  DeviceEvents(const DeviceEvents&) = delete;
  DeviceEvents& operator=(const DeviceEvents&) = delete;

  /// Registers with OpenNI2; false when it refuses.
  bool attach();
  void detach();

  void onDeviceStateChanged(const openni::DeviceInfo* info, openni::DeviceState state) override;
  void onDeviceDisconnected(const openni::DeviceInfo* info) override;

  bool end_of_file() const noexcept { return end_of_file_.load(std::memory_order_acquire); }
  bool disconnected() const noexcept { return disconnected_.load(std::memory_order_acquire); }

 private:
  bool matches(const openni::DeviceInfo* info) const noexcept;
  std::string uri_;
  bool attached_state_ = false;
  bool attached_disconnect_ = false;
  std::atomic<bool> end_of_file_{false};
  std::atomic<bool> disconnected_{false};
};

}  // namespace pliant::drivers::openni2::detail
