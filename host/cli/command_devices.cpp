#include "command_devices.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_registry.hpp"
#include "exit_status.hpp"

namespace pliant::cli {
namespace {

namespace fs = std::filesystem;

// Entries of `directory` whose name starts with one of `prefixes`, sorted ("" when unreadable).
std::vector<std::string> entries_with_prefix(const fs::path& directory, const std::vector<std::string>& prefixes) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(directory, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    for (const std::string& p : prefixes) {
      if (name.rfind(p, 0) == 0) names.push_back(name);
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

// CAN interfaces: network devices of ARP hardware type 280 (ARPHRD_CAN), with their state.
std::vector<std::string> can_interfaces() {
  std::vector<std::string> out;
  std::error_code ec;
  for (fs::directory_iterator it("/sys/class/net", ec), end; !ec && it != end; it.increment(ec)) {
    std::ifstream type(it->path() / "type");
    int arp_type = 0;
    if (!(type >> arp_type) || arp_type != 280) continue;
    std::ifstream state(it->path() / "operstate");
    std::string operstate;
    state >> operstate;
    out.push_back(it->path().filename().string() + (operstate.empty() ? "" : " (" + operstate + ")"));
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The registered schemes of one category, "v4l2 (opencv), video (opencv)"; "none" without any.
std::string scheme_list(const hal::DeviceRegistry& registry, hal::DeviceCategory category) {
  std::string out;
  for (const hal::SchemeInfo& s : registry.schemes(category)) {
    out += (out.empty() ? "" : ", ") + s.scheme + " (" + s.driver + ")";
  }
  return out.empty() ? "none" : out;
}

}  // namespace

DevicesCommand::DevicesCommand(CLI::App& parent) {
  app_ = parent.add_subcommand("devices", "List connected devices pliant can use");
  app_->footer(
      "USB depth cameras and USB-CAN adapters known to pliant (VID:PID table, docs/drivers/usb.md), CAN network "
      "interfaces (for --ft ati-can:IFACE@..., robotous-can:...), video devices (v4l2:...) and serial ports "
      "(robotiq-rtu:..., ft300-rtu:...), then the device schemes this build's drivers open (pliant record). An empty "
      "list is not an error.");
  app_->add_flag("--all", all_, "also list USB devices pliant does not know");
  app_->add_flag("--json", json_, "one JSON object instead of text");
}

int DevicesCommand::run() const {
  const hal::DeviceRegistry& registry = cli_registry().devices;
  std::vector<std::string> notes;
  nlohmann::json usb = nlohmann::json::array();
  std::string usb_text;
  if (registry.find_discovery("usb") != nullptr) {  // drivers/usb
    hal::DiscoveryOptions options;
    options.include_unknown = all_;
    hal::Discovery found = registry.discover("usb", options);
    for (const hal::DiscoveredDevice& r : found.devices) {
      usb.push_back({{"name", r.name},
                     {"kind", r.kind},
                     {"id", r.id},
                     {"location", r.location},
                     {"handled_by", r.handled_by},
                     {"detail", r.detail}});
    }
    notes = std::move(found.notes);
    usb_text = std::move(found.text);
  } else {
    notes.push_back("USB discovery is not in this build (Debian package libusb-1.0-0-dev)");
    usb_text = "USB: not in this build (Debian package libusb-1.0-0-dev)\n";
  }
  const std::vector<std::string> can = can_interfaces();
  const std::vector<std::string> video = entries_with_prefix("/dev", {"video"});
  const std::vector<std::string> serial = entries_with_prefix("/dev", {"ttyUSB", "ttyACM"});
  if (json_) {
    nlohmann::json j = {{"usb", usb},
                        {"notes", notes},
                        {"can", can},
                        {"video", nlohmann::json::array()},
                        {"serial", nlohmann::json::array()},
                        {"drivers", registry.drivers()},
                        {"schemes", nlohmann::json::array()}};
    for (const std::string& v : video) j["video"].push_back("/dev/" + v);
    for (const std::string& s : serial) j["serial"].push_back("/dev/" + s);
    for (const hal::SchemeInfo& s : registry.schemes()) {
      j["schemes"].push_back({{"scheme", s.scheme},
                              {"category", hal::device_category_name(s.category)},
                              {"driver", s.driver},
                              {"location", s.location},
                              {"description", s.description},
                              {"parameters", s.parameters}});
    }
    std::cout << j.dump(2) << '\n';
    return exit_ok;
  }
  std::cout << usb_text;
  if (!usb_text.empty() && usb_text.back() != '\n') std::cout << '\n';
  auto list = [](const char* title, const std::vector<std::string>& items, const char* prefix) {
    std::cout << title << ": ";
    if (items.empty()) std::cout << "none";
    for (std::size_t i = 0; i < items.size(); ++i) std::cout << (i ? ", " : "") << prefix << items[i];
    std::cout << '\n';
  };
  list("CAN interfaces", can, "");
  list("video devices", video, "/dev/");
  list("serial ports", serial, "/dev/");
  std::cout << "device schemes in this build (pliant record --color, --depth, --ft, --gripper):\n";
  for (const hal::DeviceCategory category : {hal::DeviceCategory::color_camera, hal::DeviceCategory::depth_camera,
                                             hal::DeviceCategory::force_torque, hal::DeviceCategory::gripper}) {
    std::cout << "  " << hal::device_category_name(category) << ": " << scheme_list(registry, category) << '\n';
  }
  return exit_ok;
}

}  // namespace pliant::cli
