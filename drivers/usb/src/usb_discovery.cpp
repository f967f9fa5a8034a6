#include "pliant/drivers/usb/usb_discovery.hpp"

#include <libusb.h>
#include <sys/stat.h>

#include <algorithm>

namespace pliant::drivers::usb {

struct UsbDiscovery::Impl {
  libusb_context* context = nullptr;
  libusb_hotplug_callback_handle handle = 0;
  bool registered = false;
};

namespace {

bool describe(libusb_device* device, UsbDeviceInfo& out) {
  libusb_device_descriptor descriptor{};
  if (libusb_get_device_descriptor(device, &descriptor) != LIBUSB_SUCCESS) return false;
  out.vendor_id = descriptor.idVendor;
  out.product_id = descriptor.idProduct;
  out.key.bus = libusb_get_bus_number(device);
  out.key.address = libusb_get_device_address(device);
  const int ports = libusb_get_port_numbers(device, out.key.ports.data(), static_cast<int>(out.key.ports.size()));
  out.key.port_count = ports > 0 ? static_cast<std::uint8_t>(ports) : 0;
  return true;
}

std::string no_bus_note() {
  struct stat st {};
  if (::stat("/dev/bus/usb", &st) != 0)
    return "libusb sees no USB device; /dev/bus/usb does not exist (a container without USB?)";
  return "libusb sees no USB device";
}

}  // namespace

// The hotplug callback (a friend, to reach the instance's presence set).
struct UsbDiscoveryCallback {
  static int LIBUSB_CALL on_event(libusb_context*, libusb_device* device, libusb_hotplug_event event, void* user) {
    auto* self = static_cast<UsbDiscovery*>(user);
    UsbDeviceInfo info;
    if (!describe(device, info)) {
      ++self->skipped_;
      return 0;
    }
    if (event == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED) {
      self->presence_.arrive(info, self->pending_);
    } else if (event == LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT) {
      self->presence_.leave(info.key, self->pending_);
    }
    return 0;  // stay registered
  }
};

UsbDiscovery::UsbDiscovery() : impl_(std::make_unique<Impl>()) {}

UsbDiscovery::~UsbDiscovery() {
  if (impl_->context == nullptr) return;
  if (impl_->registered) libusb_hotplug_deregister_callback(impl_->context, impl_->handle);
  libusb_exit(impl_->context);
}

bool UsbDiscovery::open() {
  if (opened_) return impl_->context != nullptr;
  opened_ = true;
  const int rc = libusb_init(&impl_->context);
  if (rc != LIBUSB_SUCCESS) {
    impl_->context = nullptr;
    note_ = std::string("libusb_init failed: ") + libusb_error_name(rc) + " (no USB access here?)";
    return false;
  }
  return true;
}

bool UsbDiscovery::usable() const noexcept { return impl_->context != nullptr; }

std::vector<UsbDeviceInfo> UsbDiscovery::enumerate() {
  std::vector<UsbDeviceInfo> devices;
  if (!open()) return devices;
  libusb_device** list = nullptr;
  const ssize_t count = libusb_get_device_list(impl_->context, &list);
  if (count < 0) {
    note_ = std::string("libusb_get_device_list failed: ") + libusb_error_name(static_cast<int>(count));
    return devices;
  }
  for (ssize_t i = 0; i < count; ++i) {
    UsbDeviceInfo info;
    if (describe(list[i], info)) {
      devices.push_back(info);
    } else {
      ++skipped_;
    }
  }
  libusb_free_device_list(list, 1);
  if (devices.empty()) note_ = no_bus_note();
  return devices;
}

bool UsbDiscovery::watch() {
  if (watching_) return true;
  if (!open()) return false;
  watching_ = true;
  if (libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) != 0) {
    const int rc = libusb_hotplug_register_callback(
        impl_->context,
        static_cast<libusb_hotplug_event>(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED | LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT),
        LIBUSB_HOTPLUG_ENUMERATE, LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY,
        &UsbDiscoveryCallback::on_event, this, &impl_->handle);
    if (rc == LIBUSB_SUCCESS) {
      impl_->registered = true;
      hotplug_ = true;
      return true;
    }
    note_ = std::string("libusb hotplug registration failed (") + libusb_error_name(rc) + "): polling by enumeration";
  } else {
    note_ = "libusb has no hotplug support here: polling by enumeration";
  }
  return true;
}

void UsbDiscovery::poll(std::vector<UsbEvent>& events) {
  if (!watching_ || impl_->context == nullptr) return;
  if (hotplug_) {
    timeval zero{0, 0};
    libusb_handle_events_timeout_completed(impl_->context, &zero, nullptr);
  } else {
    presence_.reconcile(enumerate(), pending_);
  }
  events.insert(events.end(), pending_.begin(), pending_.end());
  pending_.clear();
}

}  // namespace pliant::drivers::usb
