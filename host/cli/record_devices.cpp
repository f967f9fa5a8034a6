#include "record_devices.hpp"

#include <charconv>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

#include "cli_registry.hpp"
#include "exit_status.hpp"

namespace pliant::cli {
namespace {

using nlohmann::json;

// The prefix of every message about a device: "--ft 'ati-can:can0@0x20'".
std::string who(const DeviceSpec& spec) { return std::string(device_role_option(spec.role)) + " '" + spec.text + "'"; }

// Shortest text that reads back to the same double.
std::string exact(double value) {
  char text[40];
  const std::to_chars_result end = std::to_chars(text, text + sizeof text, value);
  return std::string(text, end.ptr);
}

}  // namespace

RecordDevice::RecordDevice(DeviceSpec spec, std::string driver, std::unique_ptr<hal::OpenedDevice> opened)
    : spec_(std::move(spec)), driver_(std::move(driver)), opened_(std::move(opened)) {
  if (!opened_) throw std::logic_error("RecordDevice without a device");
}

void RecordDevice::start() {
  const hal::HalStatus status = opened_->start();
  if (status != hal::HalStatus::ok) {
    throw std::runtime_error(who(spec_) + ": cannot start (" + hal::hal_status_name(status) + ")");
  }
}

json RecordDevice::driver_info() const {
  json info = json::object();
  const hal::DeviceInfo device_info = opened_->info();  // kept: fields() refers into it
  for (const hal::DeviceInfo::Field& field : device_info.fields()) {
    json* node = &info;
    std::string name = field.name;
    for (std::size_t dot = name.find('.'); dot != std::string::npos; dot = name.find('.')) {
      node = &(*node)[name.substr(0, dot)];
      name.erase(0, dot + 1);
    }
    std::visit([&](const auto& value) { (*node)[name] = value; }, field.value);
  }
  return info;
}

hal::DeviceCategory device_category(DeviceRole role) noexcept {
  switch (role) {
    case DeviceRole::color: return hal::DeviceCategory::color_camera;
    case DeviceRole::depth: return hal::DeviceCategory::depth_camera;
    case DeviceRole::ft: return hal::DeviceCategory::force_torque;
    case DeviceRole::gripper: return hal::DeviceCategory::gripper;
  }
  return hal::DeviceCategory::color_camera;
}

hal::DeviceSpec to_hal_spec(const DeviceSpec& spec, const DeviceOpenOptions& options) {
  hal::DeviceSpec s;
  s.scheme = device_kind_name(spec.kind);
  s.location = spec.location;
  auto& p = s.parameters;
  switch (spec.kind) {
    case DeviceKind::v4l2: p["format"] = "bgr8"; break;
    case DeviceKind::video:
    case DeviceKind::images:
      p["format"] = "bgr8";
      p["playback"] = "real_time";
      break;
    case DeviceKind::libcamera:
      s.location = spec.any ? "any" : spec.location;
      p["format"] = "bgr8";
      break;
    case DeviceKind::openni2: break;
    case DeviceKind::oni: p["playback"] = "real_time"; break;
    case DeviceKind::ati_can:
      p["base_id"] = std::to_string(spec.can_id);
      p["tare"] = options.tare ? "true" : "false";
      break;
    case DeviceKind::robotous_can:
      p["command_id"] = std::to_string(spec.can_id);
      p["response_1"] = std::to_string(spec.can_response_1);
      p["response_2"] = std::to_string(spec.can_response_2);
      p["tare"] = options.tare ? "true" : "false";
      break;
    case DeviceKind::ft300_tcp: p["port"] = std::to_string(spec.port); [[fallthrough]];
    case DeviceKind::ft300_rtu:
      p["slave"] = std::to_string(spec.slave_id);
      p["tare"] = options.tare ? "true" : "false";
      break;
    case DeviceKind::robotiq_tcp: p["port"] = std::to_string(spec.port); [[fallthrough]];
    case DeviceKind::robotiq_rtu:
      p["slave"] = std::to_string(spec.slave_id);
      p["stroke_m"] = exact(options.gripper_stroke_m);
      break;
  }
  return s;
}

void check_driver_built(const DeviceSpec& spec) {
  if (cli_registry().devices.find(device_category(spec.role), device_kind_name(spec.kind)) != nullptr) return;
  throw UsageError(who(spec) + ": this pliant was built without drivers/" + device_kind_driver(spec.kind) +
                   "; install " + device_kind_package(spec.kind) + " and rebuild");
}

std::unique_ptr<RecordDevice> open_device(const DeviceSpec& spec, const hal::Clock& clock,
                                          const DeviceOpenOptions& options) {
  check_driver_built(spec);
  hal::OpenResult opened = cli_registry().devices.open(device_category(spec.role), to_hal_spec(spec, options), clock);
  if (!opened) {
    const std::string message = who(spec) + ": cannot open (" + hal::hal_status_name(opened.status) + ")" +
                                (opened.error.empty() ? std::string() : ": " + opened.error);
    if (opened.status == hal::HalStatus::invalid_argument) throw UsageError(message);
    throw std::runtime_error(message);
  }
  return std::make_unique<RecordDevice>(spec, std::move(opened.driver), std::move(opened.device));
}

}  // namespace pliant::cli
