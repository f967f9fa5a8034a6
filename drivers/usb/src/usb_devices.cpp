#include "pliant/drivers/usb/usb_devices.hpp"

#include <algorithm>
#include <cstdio>

#include "pliant/drivers/usb/usb_discovery.hpp"
#include "pliant/drivers/usb/usb_ids.hpp"
#include "pliant/drivers/usb/usb_sysfs.hpp"

namespace pliant::drivers::usb {
namespace {

std::string hex4(std::uint16_t value) {
  char text[8];
  std::snprintf(text, sizeof text, "%04x", static_cast<unsigned>(value));
  return text;
}

std::string dec3(unsigned value) {
  char text[8];
  std::snprintf(text, sizeof text, "%03u", value);
  return text;
}

void append(std::string& text, const std::string& part) {
  if (part.empty()) return;
  if (!text.empty()) text += "; ";
  text += part;
}

}  // namespace

std::vector<UsbDeviceRow> describe_usb_devices(const std::vector<UsbDeviceInfo>& devices,
                                               const UsbRowOptions& options) {
  std::vector<UsbDeviceRow> rows;
  for (const UsbDeviceInfo& device : devices) {
    const UsbIdEntry* entry = lookup_usb_id(device.vendor_id, device.product_id);
    if (entry == nullptr && !options.include_unknown) continue;
    UsbDeviceRow row;
    row.device = device;
    row.name = entry != nullptr ? entry->name : "unknown device";
    row.kind = entry != nullptr ? usb_device_kind_name(entry->kind) : "other";
    row.id = hex4(device.vendor_id) + ":" + hex4(device.product_id);
    row.location = dec3(device.key.bus) + "/" + dec3(device.key.address) + " " + usb_sysfs_name(device.key);
    row.handled_by = entry != nullptr ? entry->handled_by : "none";
    if (entry != nullptr) append(row.detail, entry->note);
    if (!options.sysfs_root.empty()) {
      const UsbSysfsInfo sysfs = read_usb_sysfs(options.sysfs_root, device.key);
      if (!sysfs.product.empty()) append(row.detail, "product \"" + sysfs.product + "\"");
      if (!sysfs.serial.empty()) append(row.detail, "serial " + sysfs.serial);
      for (const std::string& interface : sysfs.net_interfaces) append(row.detail, "interface " + interface);
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

std::vector<UsbDeviceRow> list_usb_devices(const UsbRowOptions& options, std::vector<std::string>& notes) {
  UsbDiscovery discovery;
  const std::vector<UsbDeviceInfo> devices = discovery.enumerate();
  if (!discovery.note().empty()) notes.push_back(discovery.note());
  std::vector<UsbDeviceRow> rows = describe_usb_devices(devices, options);
  if (rows.empty() && !devices.empty()) {
    notes.push_back(std::to_string(devices.size()) + " USB device(s) connected, none of a kind pliant knows");
  }
  return rows;
}

std::string format_usb_device_table(const std::vector<UsbDeviceRow>& rows, const std::vector<std::string>& notes) {
  std::string text;
  if (rows.empty()) {
    text = "no known USB devices found\n";
  } else {
    const char* headers[] = {"NAME", "KIND", "VID:PID", "BUS/ADDR PORT", "DRIVER", "DETAIL"};
    std::size_t widths[5];
    for (std::size_t c = 0; c < 5; ++c) widths[c] = std::char_traits<char>::length(headers[c]);
    for (const UsbDeviceRow& row : rows) {
      const std::string* cells[] = {&row.name, &row.kind, &row.id, &row.location, &row.handled_by};
      for (std::size_t c = 0; c < 5; ++c) widths[c] = std::max(widths[c], cells[c]->size());
    }
    const auto line = [&](const std::string* cells[6]) {
      for (std::size_t c = 0; c < 5; ++c) {
        text += *cells[c];
        text.append(widths[c] - cells[c]->size() + 2, ' ');
      }
      text += *cells[5];
      while (!text.empty() && text.back() == ' ') text.pop_back();
      text += '\n';
    };
    std::string header_cells[6];
    const std::string* header_row[6];
    for (std::size_t c = 0; c < 6; ++c) {
      header_cells[c] = headers[c];
      header_row[c] = &header_cells[c];
    }
    line(header_row);
    for (const UsbDeviceRow& row : rows) {
      const std::string* cells[6] = {&row.name, &row.kind, &row.id, &row.location, &row.handled_by, &row.detail};
      line(cells);
    }
  }
  for (const std::string& note : notes) text += "note: " + note + "\n";
  return text;
}

}  // namespace pliant::drivers::usb
