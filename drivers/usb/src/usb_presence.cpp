#include "pliant/drivers/usb/usb_presence.hpp"

#include <algorithm>

namespace pliant::drivers::usb {
namespace {

bool same_ids(const UsbDeviceInfo& a, const UsbDeviceInfo& b) noexcept {
  return a.vendor_id == b.vendor_id && a.product_id == b.product_id;
}

}  // namespace

bool UsbDeviceKey::operator==(const UsbDeviceKey& other) const noexcept {
  if (bus != other.bus || address != other.address || port_count != other.port_count) return false;
  const std::size_t n = std::min<std::size_t>(port_count, ports.size());
  return std::equal(ports.begin(), ports.begin() + static_cast<std::ptrdiff_t>(n), other.ports.begin());
}

std::string usb_sysfs_name(const UsbDeviceKey& key) {
  if (key.port_count == 0) return "usb" + std::to_string(key.bus);
  std::string name = std::to_string(key.bus) + "-";
  const std::size_t n = std::min<std::size_t>(key.port_count, key.ports.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) name += '.';
    name += std::to_string(key.ports[i]);
  }
  return name;
}

void UsbPresence::arrive(const UsbDeviceInfo& device, std::vector<UsbEvent>& events) {
  const auto at = std::find_if(present_.begin(), present_.end(),
                               [&](const UsbDeviceInfo& known) { return known.key == device.key; });
  if (at != present_.end()) {
    if (same_ids(*at, device)) {
      ++counters_.duplicates;
      return;
    }
    events.push_back({UsbEventKind::left, *at});
    ++counters_.departures;
    present_.erase(at);
  }
  present_.push_back(device);
  events.push_back({UsbEventKind::arrived, device});
  ++counters_.arrivals;
}

void UsbPresence::leave(const UsbDeviceKey& key, std::vector<UsbEvent>& events) {
  const auto at =
      std::find_if(present_.begin(), present_.end(), [&](const UsbDeviceInfo& known) { return known.key == key; });
  if (at == present_.end()) {
    ++counters_.duplicates;
    return;
  }
  events.push_back({UsbEventKind::left, *at});
  ++counters_.departures;
  present_.erase(at);
}

void UsbPresence::reconcile(const std::vector<UsbDeviceInfo>& now, std::vector<UsbEvent>& events) {
  const auto in_now = [&](const UsbDeviceInfo& known) {
    return std::any_of(now.begin(), now.end(),
                       [&](const UsbDeviceInfo& d) { return d.key == known.key && same_ids(d, known); });
  };
  // Departures first, so that a replaced device reads as left-then-arrived.
  for (std::size_t i = 0; i < present_.size();) {
    if (in_now(present_[i])) {
      ++i;
      continue;
    }
    events.push_back({UsbEventKind::left, present_[i]});
    ++counters_.departures;
    present_.erase(present_.begin() + static_cast<std::ptrdiff_t>(i));
  }
  for (const UsbDeviceInfo& device : now) {
    const bool known =
        std::any_of(present_.begin(), present_.end(), [&](const UsbDeviceInfo& p) { return p.key == device.key; });
    if (known) continue;  // present already, or listed twice in `now`
    present_.push_back(device);
    events.push_back({UsbEventKind::arrived, device});
    ++counters_.arrivals;
  }
}

}  // namespace pliant::drivers::usb
