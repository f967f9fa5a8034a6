#include "pliant/drivers/usb/usb_sysfs.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>

namespace pliant::drivers::usb {
namespace {

namespace fs = std::filesystem;

std::string read_attribute(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return {};
  char buffer[255];
  in.read(buffer, sizeof buffer);
  const std::size_t got = static_cast<std::size_t>(in.gcount());
  std::string value;
  for (std::size_t i = 0; i < got; ++i) {
    const unsigned char c = static_cast<unsigned char>(buffer[i]);
    if (c == '\n' || c == '\r' || c == 0) break;
    value.push_back(c >= 0x20 && c <= 0x7E ? static_cast<char>(c) : '?');
  }
  return value;
}

}  // namespace

UsbSysfsInfo read_usb_sysfs(const std::string& sysfs_root, const UsbDeviceKey& key) {
  UsbSysfsInfo info;
  std::error_code ec;
  const fs::path devices = fs::path(sysfs_root) / "bus" / "usb" / "devices";
  const std::string name = usb_sysfs_name(key);
  const fs::path device = devices / name;
  if (!fs::is_directory(device, ec)) return info;
  info.found = true;
  info.manufacturer = read_attribute(device / "manufacturer");
  info.product = read_attribute(device / "product");
  info.serial = read_attribute(device / "serial");

  // Interfaces are siblings named "<name>:<config>.<interface>".
  const std::string prefix = name + ":";
  for (fs::directory_iterator it(devices, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    if (entry.compare(0, prefix.size(), prefix) != 0) continue;
    const fs::path net = it->path() / "net";
    std::error_code net_ec;
    for (fs::directory_iterator nit(net, net_ec), nend; !net_ec && nit != nend; nit.increment(net_ec)) {
      info.net_interfaces.push_back(nit->path().filename().string());
    }
  }
  std::sort(info.net_interfaces.begin(), info.net_interfaces.end());
  return info;
}

}  // namespace pliant::drivers::usb
