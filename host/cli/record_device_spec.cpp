#include "record_device_spec.hpp"

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace pliant::cli {
namespace {

// A spec longer than this is refused before anything else (paths are far shorter).
constexpr std::size_t kMaxSpecLength = 4096;
// Characters of the spec shown in messages.
constexpr std::size_t kShownLength = 120;

struct KindEntry {
  const char* word;
  DeviceKind kind;
  DeviceRole role;
  const char* form;     // expected form
  const char* example;  // an example spec
  const char* driver;   // the drivers/ folder that opens it
  const char* package;  // the Debian package that driver needs
};

constexpr KindEntry kKinds[] = {
    {"v4l2", DeviceKind::v4l2, DeviceRole::color, "v4l2:/dev/videoN or v4l2:N", "v4l2:/dev/video0", "opencv",
     "libopencv-dev"},
    {"video", DeviceKind::video, DeviceRole::color, "video:FILE", "video:take1.avi", "opencv", "libopencv-dev"},
    {"images", DeviceKind::images, DeviceRole::color, "images:PATTERN", "images:frames/f_%04d.png", "opencv",
     "libopencv-dev"},
    {"libcamera", DeviceKind::libcamera, DeviceRole::color, "libcamera:any or libcamera:ID", "libcamera:any",
     "libcamera", "libcamera-dev"},
    {"openni2", DeviceKind::openni2, DeviceRole::depth, "openni2:any or openni2:URI", "openni2:any", "openni2",
     "libopenni2-dev"},
    {"oni", DeviceKind::oni, DeviceRole::depth, "oni:FILE", "oni:take1.oni", "openni2", "libopenni2-dev"},
    {"ati-can", DeviceKind::ati_can, DeviceRole::ft, "ati-can:IFACE@0xBASE", "ati-can:can0@0x20", "socketcan",
     "linux-libc-dev"},
    {"robotous-can", DeviceKind::robotous_can, DeviceRole::ft, "robotous-can:IFACE@0xCMD[,0xRESP1,0xRESP2]",
     "robotous-can:can0@0x64", "socketcan", "linux-libc-dev"},
    {"ft300-rtu", DeviceKind::ft300_rtu, DeviceRole::ft, "ft300-rtu:DEV[@SLAVE]", "ft300-rtu:/dev/ttyUSB1", "modbus",
     "libmodbus-dev"},
    {"ft300-tcp", DeviceKind::ft300_tcp, DeviceRole::ft, "ft300-tcp:HOST:PORT[@SLAVE]", "ft300-tcp:192.168.1.11:502",
     "modbus", "libmodbus-dev"},
    {"robotiq-rtu", DeviceKind::robotiq_rtu, DeviceRole::gripper, "robotiq-rtu:DEV[@SLAVE]", "robotiq-rtu:/dev/ttyUSB0",
     "modbus", "libmodbus-dev"},
    {"robotiq-tcp", DeviceKind::robotiq_tcp, DeviceRole::gripper, "robotiq-tcp:HOST:PORT[@SLAVE]",
     "robotiq-tcp:192.168.1.11:502", "modbus", "libmodbus-dev"},
};

const KindEntry& entry_of(DeviceKind kind) {
  for (const KindEntry& e : kKinds) {
    if (e.kind == kind) return e;
  }
  return kKinds[0];  // unreachable: every kind has an entry
}

// The spec as shown in messages: control and non-ASCII bytes escaped, cut after kShownLength
// characters of output.
std::string shown(std::string_view text) {
  static const char digits[] = "0123456789abcdef";
  std::string out;
  std::size_t i = 0;
  for (; i < text.size() && out.size() < kShownLength; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c >= 0x7f) {
      out += "\\x";
      out += digits[c >> 4];
      out += digits[c & 0xf];
    } else {
      out += static_cast<char>(c);
    }
  }
  if (i < text.size()) out += "...";
  return out;
}

class Parser {
 public:
  Parser(DeviceRole role, std::string_view text) : role_(role), text_(text) {}

  [[noreturn]] void fail(const std::string& cause) const {
    throw DeviceSpecError(std::string(device_role_option(role_)) + " '" + shown(text_) + "': " + cause);
  }
  [[noreturn]] void fail_form(const KindEntry& e, const std::string& detail = "") const {
    fail((detail.empty() ? std::string() : detail + "; ") + "expected " + e.form + " (e.g. " + e.example + ")");
  }

  std::string kinds_of_role() const {
    std::string list;
    for (const KindEntry& e : kKinds) {
      if (e.role == role_) list += (list.empty() ? "" : ", ") + std::string(e.word);
    }
    return list;
  }

  DeviceSpec parse() const {
    if (text_.size() > kMaxSpecLength) fail("longer than " + std::to_string(kMaxSpecLength) + " characters");
    for (const char ch : text_) {
      const auto c = static_cast<unsigned char>(ch);
      if (c < 0x20 || c == 0x7f) fail("contains a control character");
    }
    const std::size_t colon = text_.find(':');
    if (colon == std::string_view::npos) {
      fail(std::string("expected KIND:LOCATION; ") + device_role_option(role_) + " takes " + kinds_of_role());
    }
    const std::string_view word = text_.substr(0, colon);
    const std::string_view rest = text_.substr(colon + 1);
    const KindEntry* found = nullptr;
    for (const KindEntry& e : kKinds) {
      if (word == e.word) found = &e;
    }
    if (found == nullptr) {
      fail("unknown kind '" + shown(word) + "'; " + device_role_option(role_) + " takes " + kinds_of_role());
    }
    if (found->role != role_) {
      fail("'" + std::string(found->word) + "' is a " + device_role_option(found->role) + " device; " +
           device_role_option(role_) + " takes " + kinds_of_role());
    }
    DeviceSpec spec;
    spec.role = role_;
    spec.kind = found->kind;
    spec.text = std::string(text_);
    if (rest.empty()) fail_form(*found, "nothing after '" + std::string(found->word) + ":'");
    switch (found->kind) {
      case DeviceKind::v4l2: parse_v4l2(*found, rest, spec); break;
      case DeviceKind::video:
      case DeviceKind::images:
      case DeviceKind::oni: spec.location = std::string(rest); break;
      case DeviceKind::libcamera:
        spec.any = rest == "any";
        spec.location = spec.any ? std::string() : std::string(rest);
        break;
      case DeviceKind::openni2:
        spec.any = rest == "any";
        spec.location = std::string(rest);
        break;
      case DeviceKind::ati_can: parse_ati(*found, rest, spec); break;
      case DeviceKind::robotous_can: parse_robotous(*found, rest, spec); break;
      case DeviceKind::ft300_rtu:
      case DeviceKind::robotiq_rtu: parse_rtu(*found, rest, spec); break;
      case DeviceKind::ft300_tcp:
      case DeviceKind::robotiq_tcp: parse_tcp(*found, rest, spec); break;
    }
    return spec;
  }

 private:
  static bool all_digits(std::string_view s) {
    if (s.empty()) return false;
    for (const char c : s) {
      if (c < '0' || c > '9') return false;
    }
    return true;
  }

  // Decimal digits, at most `max`; nullopt otherwise (no sign, no blanks, no overflow).
  static std::optional<std::uint32_t> decimal(std::string_view s, std::uint32_t max) {
    if (!all_digits(s) || s.size() > 10) return std::nullopt;
    std::uint64_t value = 0;
    for (const char c : s) value = value * 10 + static_cast<std::uint64_t>(c - '0');
    if (value > max) return std::nullopt;
    return static_cast<std::uint32_t>(value);
  }

  // 0x-prefixed hexadecimal or decimal, at most `max`.
  static std::optional<std::uint32_t> can_number(std::string_view s, std::uint32_t max) {
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
      const std::string_view digits = s.substr(2);
      if (digits.size() > 8) return std::nullopt;
      std::uint64_t value = 0;
      for (const char c : digits) {
        int d = -1;
        if (c >= '0' && c <= '9') d = c - '0';
        if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
        if (c >= 'A' && c <= 'F') d = c - 'A' + 10;
        if (d < 0) return std::nullopt;
        value = value * 16 + static_cast<std::uint64_t>(d);
      }
      if (value > max) return std::nullopt;
      return static_cast<std::uint32_t>(value);
    }
    return decimal(s, max);
  }

  void parse_v4l2(const KindEntry& e, std::string_view rest, DeviceSpec& spec) const {
    if (all_digits(rest)) {
      if (rest.size() > 4) fail_form(e, "device index too large");
    } else if (rest.size() <= 5 || rest.substr(0, 5) != "/dev/") {
      fail_form(e);
    }
    spec.location = std::string(rest);
  }

  void check_interface(const KindEntry& e, std::string_view iface) const {
    if (iface.empty()) fail_form(e, "no interface name");
    if (iface.size() > 15) fail_form(e, "interface name longer than 15 characters");
    for (const char c : iface) {
      if (c == '/' || c == ' ' || c == ':' || c == '@' || c == ',') fail_form(e, "bad interface name");
    }
  }

  void parse_ati(const KindEntry& e, std::string_view rest, DeviceSpec& spec) const {
    const std::size_t at = rest.rfind('@');
    if (at == std::string_view::npos) fail_form(e, "no base ID");
    check_interface(e, rest.substr(0, at));
    const auto base = can_number(rest.substr(at + 1), 0x7f);
    if (!base) fail_form(e, "base ID must be 0..0x7f");
    spec.location = std::string(rest.substr(0, at));
    spec.can_id = *base;
  }

  void parse_robotous(const KindEntry& e, std::string_view rest, DeviceSpec& spec) const {
    const std::size_t at = rest.rfind('@');
    if (at == std::string_view::npos) fail_form(e, "no command ID");
    check_interface(e, rest.substr(0, at));
    std::vector<std::string_view> ids;
    std::string_view list = rest.substr(at + 1);
    for (;;) {
      const std::size_t comma = list.find(',');
      ids.push_back(list.substr(0, comma));
      if (comma == std::string_view::npos) break;
      list = list.substr(comma + 1);
    }
    if (ids.size() != 1 && ids.size() != 3) fail_form(e, "give the command ID alone or with both response IDs");
    std::uint32_t values[3] = {0, 0x01, 0x02};
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const auto value = can_number(ids[i], 0x7ff);
      if (!value) fail_form(e, "CAN IDs must be standard IDs 0..0x7ff");
      values[i] = *value;
    }
    if (values[0] == values[1] || values[0] == values[2] || values[1] == values[2]) {
      fail_form(e, "the three CAN IDs must differ");
    }
    spec.location = std::string(rest.substr(0, at));
    spec.can_id = values[0];
    spec.can_response_1 = values[1];
    spec.can_response_2 = values[2];
  }

  // Splits "...@SLAVE" off `rest` when there is an '@' (the slave must then be valid).
  std::string_view take_slave(const KindEntry& e, std::string_view rest, DeviceSpec& spec) const {
    const std::size_t at = rest.rfind('@');
    if (at == std::string_view::npos) return rest;
    const auto slave = decimal(rest.substr(at + 1), 247);
    if (!slave) fail_form(e, "SLAVE must be a decimal Modbus slave ID 0..247");
    spec.slave_id = static_cast<int>(*slave);
    return rest.substr(0, at);
  }

  void parse_rtu(const KindEntry& e, std::string_view rest, DeviceSpec& spec) const {
    const std::string_view device = take_slave(e, rest, spec);
    if (device.empty()) fail_form(e, "no serial device");
    spec.location = std::string(device);
  }

  static bool dotted_quad(std::string_view host) {
    int parts = 0;
    for (;;) {
      const std::size_t dot = host.find('.');
      const std::string_view part = host.substr(0, dot);
      if (part.size() > 3 || !decimal(part, 255)) return false;
      ++parts;
      if (dot == std::string_view::npos) break;
      host = host.substr(dot + 1);
    }
    return parts == 4;
  }

  void parse_tcp(const KindEntry& e, std::string_view rest, DeviceSpec& spec) const {
    const std::string_view address = take_slave(e, rest, spec);
    const std::size_t colon = address.rfind(':');
    if (colon == std::string_view::npos) fail_form(e, "no port");
    const std::string_view host = address.substr(0, colon);
    if (!dotted_quad(host)) fail_form(e, "HOST must be a dotted IPv4 address (no name lookup)");
    const auto port = decimal(address.substr(colon + 1), 65535);
    if (!port || *port == 0) fail_form(e, "PORT must be 1..65535");
    spec.location = std::string(host);
    spec.port = static_cast<int>(*port);
  }

  DeviceRole role_;
  std::string_view text_;
};

}  // namespace

DeviceSpec parse_device_spec(DeviceRole role, std::string_view text) { return Parser(role, text).parse(); }

const char* device_role_option(DeviceRole role) noexcept {
  switch (role) {
    case DeviceRole::color: return "--color";
    case DeviceRole::depth: return "--depth";
    case DeviceRole::ft: return "--ft";
    case DeviceRole::gripper: return "--gripper";
  }
  return "--?";
}

const char* device_role_name(DeviceRole role) noexcept { return device_role_option(role) + 2; }

const char* device_kind_name(DeviceKind kind) noexcept { return entry_of(kind).word; }

const char* device_kind_driver(DeviceKind kind) noexcept { return entry_of(kind).driver; }

const char* device_kind_package(DeviceKind kind) noexcept { return entry_of(kind).package; }

bool is_file_backed(DeviceKind kind) noexcept {
  return kind == DeviceKind::video || kind == DeviceKind::images || kind == DeviceKind::oni;
}

}  // namespace pliant::cli
