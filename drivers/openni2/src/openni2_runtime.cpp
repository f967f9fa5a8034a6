#include "openni2_runtime.hpp"

#include <dlfcn.h>

#include <cstring>
#include <fstream>
#include <mutex>

#include "pliant/drivers/openni2/openni2_camera.hpp"

namespace pliant::drivers::openni2 {
namespace detail {
namespace {

std::mutex g_init_mutex;
bool g_initialised = false;

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

// [Drivers] Repository= of Debian's OpenNI.ini (the path libOpenNI2 is patched to read), or "".
std::string ini_repository() {
  std::ifstream ini("/etc/openni2/OpenNI.ini");
  std::string line;
  bool in_drivers = false;
  while (std::getline(ini, line)) {
    line = trim(line);
    if (line.empty() || line[0] == ';') continue;
    if (line[0] == '[') {
      in_drivers = line == "[Drivers]";
      continue;
    }
    if (in_drivers && line.rfind("Repository", 0) == 0) {
      const auto equals = line.find('=');
      if (equals != std::string::npos) return trim(line.substr(equals + 1));
    }
  }
  return {};
}

}  // namespace

bool ensure_openni2(std::string& error) {
  const std::lock_guard<std::mutex> lock(g_init_mutex);
  if (g_initialised) return true;
  const openni::Status status = openni::OpenNI::initialize();
  if (status == openni::STATUS_OK) {
    g_initialised = true;
    return true;
  }
  error = std::string("OpenNI2 failed to initialise: ") + openni::OpenNI::getExtendedError();
  const std::string directory = openni2_driver_directory();
  if (!directory.empty()) error += " (driver directory: " + directory + ")";
  // initialize() counts calls even when it fails; balance it so that the next attempt reloads.
  openni::OpenNI::shutdown();
  return false;
}

bool DeviceEvents::attach() {
  if (!attached_state_) attached_state_ = openni::OpenNI::addDeviceStateChangedListener(this) == openni::STATUS_OK;
  if (!attached_disconnect_) {
    attached_disconnect_ = openni::OpenNI::addDeviceDisconnectedListener(this) == openni::STATUS_OK;
  }
  return attached_state_ && attached_disconnect_;
}

void DeviceEvents::detach() {
  if (attached_state_) openni::OpenNI::removeDeviceStateChangedListener(this);
  if (attached_disconnect_) openni::OpenNI::removeDeviceDisconnectedListener(this);
  attached_state_ = attached_disconnect_ = false;
}

bool DeviceEvents::matches(const openni::DeviceInfo* info) const noexcept {
  return info != nullptr && info->getUri() != nullptr && uri_ == info->getUri();
}

void DeviceEvents::onDeviceStateChanged(const openni::DeviceInfo* info, openni::DeviceState state) {
  if (state == openni::DEVICE_STATE_EOF && matches(info)) end_of_file_.store(true, std::memory_order_release);
}

void DeviceEvents::onDeviceDisconnected(const openni::DeviceInfo* info) {
  if (matches(info)) disconnected_.store(true, std::memory_order_release);
}

}  // namespace detail

std::string openni2_driver_directory() {
  // The directory of the libOpenNI2 this process loaded (found from one of its functions).
  Dl_info where{};
  void* symbol = nullptr;
  auto* function = &oniInitialize;
  static_assert(sizeof symbol == sizeof function, "function and data pointers differ in size");
  std::memcpy(&symbol, &function, sizeof symbol);
  if (dladdr(symbol, &where) == 0 || where.dli_fname == nullptr) return {};
  std::string library = where.dli_fname;
  const auto slash = library.rfind('/');
  const std::string library_dir = slash == std::string::npos ? std::string(".") : library.substr(0, slash);
  std::string repository = detail::ini_repository();
  if (repository.empty()) repository = "OpenNI2/Drivers";
  if (repository[0] == '/') return repository;
  return library_dir + "/" + repository;
}

bool list_openni2_devices(std::vector<Openni2DeviceEntry>& out, std::string& error) {
  out.clear();
  if (!detail::ensure_openni2(error)) return false;
  openni::Array<openni::DeviceInfo> devices;
  openni::OpenNI::enumerateDevices(&devices);
  for (int i = 0; i < devices.getSize(); ++i) {
    const openni::DeviceInfo& info = devices[i];
    Openni2DeviceEntry entry;
    entry.uri = info.getUri() != nullptr ? info.getUri() : "";
    entry.name = info.getName() != nullptr ? info.getName() : "";
    entry.vendor = info.getVendor() != nullptr ? info.getVendor() : "";
    entry.usb_vendor_id = info.getUsbVendorId();
    entry.usb_product_id = info.getUsbProductId();
    out.push_back(std::move(entry));
  }
  return true;
}

}  // namespace pliant::drivers::openni2
