#include "pliant/drivers/usb/usb_registration.hpp"

#include <string>
#include <vector>

#include "pliant/drivers/usb/usb_devices.hpp"

namespace pliant::drivers {

void register_usb_devices(hal::DeviceRegistry& registry) {
  registry.add_discovery({"usb", "usb", "USB depth cameras and USB-CAN adapters (libusb, VID:PID table, sysfs)"},
                         [](const hal::DiscoveryOptions& options) {
                           usb::UsbRowOptions row_options;
                           row_options.include_unknown = options.include_unknown;
                           hal::Discovery found;
                           const std::vector<usb::UsbDeviceRow> rows = usb::list_usb_devices(row_options, found.notes);
                           for (const usb::UsbDeviceRow& r : rows) {
                             found.devices.push_back({r.name, r.kind, r.id, r.location, r.handled_by, r.detail});
                           }
                           found.text = usb::format_usb_device_table(rows, found.notes);
                           return found;
                         });
}

}  // namespace pliant::drivers
