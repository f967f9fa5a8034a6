#include "pliant/hal/device_registry.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <system_error>
#include <utility>

namespace pliant::hal {
namespace {

// At most this many characters of a value in a message (values come from command lines).
constexpr std::size_t kShownValue = 60;

std::string shown(std::string_view value) {
  std::string out;
  for (const char ch : value.substr(0, kShownValue)) {
    const auto c = static_cast<unsigned char>(ch);
    out += (c < 0x20 || c >= 0x7f) ? '?' : ch;
  }
  if (value.size() > kShownValue) out += "...";
  return out;
}

[[noreturn]] void malformed(std::string_view name, std::string_view value, const std::string& expected) {
  throw std::invalid_argument("parameter '" + std::string(name) + "' = '" + shown(value) + "': expected " + expected);
}

std::string range_text(std::int64_t min, std::int64_t max) { return std::to_string(min) + ".." + std::to_string(max); }

// Decimal, or hexadecimal with 0x; nothing else (no sign for hexadecimal, no blanks).
bool parse_integer(std::string_view text, std::int64_t& out) {
  int base = 10;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    text.remove_prefix(2);
    if (text.front() == '-' || text.front() == '+') return false;
  }
  if (text.empty()) return false;
  const std::from_chars_result r = std::from_chars(text.data(), text.data() + text.size(), out, base);
  return r.ec == std::errc() && r.ptr == text.data() + text.size();
}

bool valid_scheme(std::string_view scheme) {
  if (scheme.empty()) return false;
  for (const char c : scheme) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-')) return false;
  }
  return true;
}

std::string joined(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

}  // namespace

const char* device_category_name(DeviceCategory category) noexcept {
  switch (category) {
    case DeviceCategory::color_camera: return "colour camera";
    case DeviceCategory::depth_camera: return "depth camera";
    case DeviceCategory::force_torque: return "force/torque sensor";
    case DeviceCategory::gripper: return "gripper";
  }
  return "device";
}

// --- DeviceSpec ---

bool DeviceSpec::has(std::string_view name) const { return parameters.find(name) != parameters.end(); }

std::string DeviceSpec::text(std::string_view name, std::string_view fallback) const {
  const auto it = parameters.find(name);
  return it == parameters.end() ? std::string(fallback) : it->second;
}

std::int64_t DeviceSpec::integer(std::string_view name, std::int64_t min, std::int64_t max,
                                 std::int64_t fallback) const {
  const auto it = parameters.find(name);
  if (it == parameters.end()) return fallback;
  std::int64_t value = 0;
  if (!parse_integer(it->second, value) || value < min || value > max) {
    malformed(name, it->second, "an integer " + range_text(min, max));
  }
  return value;
}

std::int64_t DeviceSpec::integer(std::string_view name, std::int64_t min, std::int64_t max) const {
  if (!has(name)) {
    throw std::invalid_argument("parameter '" + std::string(name) + "' missing: expected an integer " +
                                range_text(min, max));
  }
  return integer(name, min, max, 0);
}

double DeviceSpec::number(std::string_view name, double min, double max, double fallback) const {
  const auto it = parameters.find(name);
  if (it == parameters.end()) return fallback;
  const std::string& text_value = it->second;
  double value = 0;
  const std::from_chars_result r =
      std::from_chars(text_value.data(), text_value.data() + text_value.size(), value, std::chars_format::general);
  if (text_value.empty() || r.ec != std::errc() || r.ptr != text_value.data() + text_value.size() ||
      !std::isfinite(value) || value < min || value > max) {
    char range[64];
    std::snprintf(range, sizeof range, "a number %g..%g", min, max);
    malformed(name, text_value, range);
  }
  return value;
}

bool DeviceSpec::flag(std::string_view name, bool fallback) const {
  const auto it = parameters.find(name);
  if (it == parameters.end()) return fallback;
  const std::string& v = it->second;
  if (v == "1" || v == "true" || v == "yes" || v == "on") return true;
  if (v == "0" || v == "false" || v == "no" || v == "off") return false;
  malformed(name, v, "true or false");
}

std::string DeviceSpec::choice(std::string_view name, std::initializer_list<std::string_view> choices,
                               std::string_view fallback) const {
  const auto it = parameters.find(name);
  if (it == parameters.end()) return std::string(fallback);
  std::string list;
  for (const std::string_view c : choices) {
    if (it->second == c) return it->second;
    list += (list.empty() ? "" : ", ") + std::string(c);
  }
  malformed(name, it->second, "one of " + list);
}

// --- DeviceInfo ---

DeviceInfo& DeviceInfo::add(std::string name, bool value) {
  fields_.push_back({std::move(name), Value(std::in_place_type<bool>, value)});
  return *this;
}

DeviceInfo& DeviceInfo::add(std::string name, double value) {
  fields_.push_back({std::move(name), Value(std::in_place_type<double>, value)});
  return *this;
}

DeviceInfo& DeviceInfo::add(std::string name, std::string value) {
  fields_.push_back({std::move(name), Value(std::in_place_type<std::string>, std::move(value))});
  return *this;
}

DeviceInfo& DeviceInfo::add_signed(std::string name, long long value) {
  fields_.push_back({std::move(name), Value(std::in_place_type<std::int64_t>, static_cast<std::int64_t>(value))});
  return *this;
}

DeviceInfo& DeviceInfo::add_unsigned(std::string name, unsigned long long value) {
  fields_.push_back({std::move(name), Value(std::in_place_type<std::uint64_t>, static_cast<std::uint64_t>(value))});
  return *this;
}

DeviceInfo& DeviceInfo::nest(const std::string& prefix, const DeviceInfo& other) {
  for (const Field& f : other.fields_) fields_.push_back({prefix + "." + f.name, f.value});
  return *this;
}

// --- OpenedDevice, OpenResult ---

HalStatus OpenedDevice::start() noexcept {
  const HalStatus status = device().start();
  if (status == HalStatus::ok) on_started();
  return status;
}

void OpenedDevice::shut_down(Device& device) noexcept {
  if (device.state() == LifecycleState::active) (void)device.stop();
  if (device.state() == LifecycleState::inactive) (void)device.cleanup();
}

OpenResult OpenResult::success(std::unique_ptr<OpenedDevice> device) {
  OpenResult r;
  r.device = std::move(device);
  if (!r.device) {
    r.status = HalStatus::io_error;
    r.error = "the driver returned no device";
  }
  return r;
}

OpenResult OpenResult::failure(HalStatus status, std::string error) {
  OpenResult r;
  r.status = status == HalStatus::ok ? HalStatus::io_error : status;
  r.error = std::move(error);
  return r;
}

// --- DeviceRegistry ---

void DeviceRegistry::add(SchemeInfo info, DeviceFactory factory) {
  if (!valid_scheme(info.scheme)) {
    throw std::invalid_argument("device registry: scheme '" + shown(info.scheme) +
                                "' must be lower-case letters, digits and '-'");
  }
  if (info.driver.empty())
    throw std::invalid_argument("device registry: scheme '" + info.scheme + "' without a driver");
  if (!factory) throw std::invalid_argument("device registry: scheme '" + info.scheme + "' without a factory");
  for (const Scheme& s : schemes_) {
    if (s.info.scheme == info.scheme) {
      throw std::invalid_argument("device registry: scheme '" + info.scheme + "' registered twice (drivers " +
                                  s.info.driver + " and " + info.driver + ")");
    }
  }
  schemes_.push_back({std::move(info), std::move(factory)});
}

void DeviceRegistry::add_discovery(DiscoveryInfo info, DiscoveryFunction function) {
  if (info.name.empty() || info.driver.empty()) {
    throw std::invalid_argument("device registry: a discovery needs a name and a driver");
  }
  if (!function) throw std::invalid_argument("device registry: discovery '" + info.name + "' without a function");
  if (find_discovery(info.name) != nullptr) {
    throw std::invalid_argument("device registry: discovery '" + info.name + "' registered twice");
  }
  discoverers_.push_back({std::move(info), std::move(function)});
}

const SchemeInfo* DeviceRegistry::find(DeviceCategory category, std::string_view scheme) const {
  for (const Scheme& s : schemes_) {
    if (s.info.category == category && s.info.scheme == scheme) return &s.info;
  }
  return nullptr;
}

std::vector<SchemeInfo> DeviceRegistry::schemes() const {
  std::vector<SchemeInfo> out;
  for (const Scheme& s : schemes_) out.push_back(s.info);
  std::sort(out.begin(), out.end(), [](const SchemeInfo& a, const SchemeInfo& b) {
    return a.category != b.category ? a.category < b.category : a.scheme < b.scheme;
  });
  return out;
}

std::vector<SchemeInfo> DeviceRegistry::schemes(DeviceCategory category) const {
  std::vector<SchemeInfo> out;
  for (SchemeInfo& s : schemes()) {
    if (s.category == category) out.push_back(std::move(s));
  }
  return out;
}

std::vector<std::string> DeviceRegistry::drivers() const {
  std::vector<std::string> out;
  for (const Scheme& s : schemes_) out.push_back(s.info.driver);
  for (const Discoverer& d : discoverers_) out.push_back(d.info.driver);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::string DeviceRegistry::unknown_scheme_message(DeviceCategory category, std::string_view scheme) const {
  for (const Scheme& s : schemes_) {
    if (s.info.scheme == scheme && s.info.category != category) {
      return "'" + s.info.scheme + "' is a " + device_category_name(s.info.category) + ", not a " +
             device_category_name(category);
    }
  }
  std::vector<std::string> names;
  for (const SchemeInfo& s : schemes(category)) names.push_back(s.scheme);
  return std::string("no ") + device_category_name(category) + " driver for '" + shown(scheme) + "' in this build (" +
         (names.empty() ? std::string("none is built") : "it has " + joined(names)) + ")";
}

OpenResult DeviceRegistry::open(DeviceCategory category, const DeviceSpec& spec, const Clock& clock) const {
  try {
    const Scheme* found = nullptr;
    for (const Scheme& s : schemes_) {
      if (s.info.category == category && s.info.scheme == spec.scheme) found = &s;
    }
    if (found == nullptr)
      return OpenResult::failure(HalStatus::unsupported, unknown_scheme_message(category, spec.scheme));
    const std::vector<std::string>& declared = found->info.parameters;
    for (const auto& parameter : spec.parameters) {
      if (std::find(declared.begin(), declared.end(), parameter.first) == declared.end()) {
        return OpenResult::failure(
            HalStatus::invalid_argument,
            spec.scheme + " has no parameter '" + shown(parameter.first) + "' (" +
                (declared.empty() ? std::string("it takes none") : "it takes " + joined(declared)) + ")");
      }
    }
    OpenResult result;
    try {
      result = found->factory(spec, clock);
    } catch (const std::invalid_argument& e) {
      result = OpenResult::failure(HalStatus::invalid_argument, e.what());
    }
    if (result.device == nullptr && result.status == HalStatus::ok) {
      result = OpenResult::failure(HalStatus::io_error, "the driver returned no device");
    }
    if (result.device != nullptr) result.status = HalStatus::ok;
    result.driver = found->info.driver;
    return result;
  } catch (const std::bad_alloc&) {
    return OpenResult::failure(HalStatus::capacity_exceeded, "out of memory");
  } catch (const std::exception& e) {
    return OpenResult::failure(HalStatus::io_error, e.what());
  } catch (...) {
    return OpenResult::failure(HalStatus::io_error, "unknown error");
  }
}

const DiscoveryInfo* DeviceRegistry::find_discovery(std::string_view name) const {
  for (const Discoverer& d : discoverers_) {
    if (d.info.name == name) return &d.info;
  }
  return nullptr;
}

std::vector<DiscoveryInfo> DeviceRegistry::discoveries() const {
  std::vector<DiscoveryInfo> out;
  for (const Discoverer& d : discoverers_) out.push_back(d.info);
  std::sort(out.begin(), out.end(), [](const DiscoveryInfo& a, const DiscoveryInfo& b) { return a.name < b.name; });
  return out;
}

Discovery DeviceRegistry::discover(std::string_view name, const DiscoveryOptions& options) const {
  Discovery none;
  try {
    for (const Discoverer& d : discoverers_) {
      if (d.info.name == name) return d.function(options);
    }
    none.notes.push_back("no discovery '" + shown(name) + "' in this build");
  } catch (const std::exception& e) {
    none = Discovery();
    none.notes.push_back(std::string(name) + " discovery failed: " + e.what());
  } catch (...) {
    none = Discovery();
    none.notes.push_back(std::string(name) + " discovery failed");
  }
  return none;
}

}  // namespace pliant::hal
