// Device specs of `pliant record`: the text KIND:LOCATION after --color, --depth, --ft and
// --gripper, parsed into a struct. Pure: no I/O, no device is touched (whether a file exists or
// an interface is up is found out when the device is opened, record_devices.hpp). Every kind is
// parsed whether or not its driver was built; record_devices.hpp turns a spec into the generic
// hal::DeviceSpec its driver registered (hal/device_registry.hpp) and refuses kinds whose driver
// this build lacks.
//
//   --color    v4l2:/dev/videoN | v4l2:N | v4l2:/dev/v4l/by-id/...   a V4L2 webcam (drivers/opencv)
//              video:FILE                 a video file, played in real time (drivers/opencv)
//              images:PATTERN             an image sequence: printf pattern or directory (drivers/opencv)
//              libcamera:any | libcamera:ID   a libcamera camera (drivers/libcamera)
//   --depth    openni2:any | openni2:URI  an OpenNI2 depth camera (drivers/openni2)
//              oni:FILE                   an .oni recording, played in real time (drivers/openni2)
//   --ft       ati-can:IFACE@0xBASE       ATI F/T with the NETCANOEM board, base ID 0..0x7f (drivers/socketcan)
//              robotous-can:IFACE@0xCMD[,0xRESP1,0xRESP2]   Robotous RFT: command ID (responses
//                                         0x01, 0x02 unless given), standard IDs (drivers/socketcan)
//              ft300-rtu:DEV[@SLAVE]      Robotiq FT 300 on a serial port, stream mode (drivers/modbus)
//              ft300-tcp:HOST:PORT[@SLAVE]  Robotiq FT 300 behind a Modbus TCP gateway, polled (drivers/modbus)
//   --gripper  robotiq-rtu:DEV[@SLAVE]    Robotiq 2F-85/140 on a serial port (drivers/modbus)
//              robotiq-tcp:HOST:PORT[@SLAVE]  Robotiq 2F through Modbus TCP (drivers/modbus)
//
// Numbers: CAN IDs are hexadecimal with 0x or decimal; SLAVE is decimal 0..247 (default 9, the
// Robotiq default); PORT decimal 1..65535; HOST a dotted IPv4 address (the Modbus driver does no
// name lookup). IFACE is a network interface name (1..15 characters, no '/', blank or ':').
//
// Errors: DeviceSpecError, whose what() is one line naming the option, the text and the cause,
// with the expected form, e.g.
//   "--ft 'ati-can:can0': expected ati-can:IFACE@0xBASE (e.g. ati-can:can0@0x20)"
// The command line reports it with exit status 2.
// Thread safety: pure functions, safe from any thread.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace pliant::cli {

/// Which option a spec came from (what the device is for in the recording).
enum class DeviceRole : std::uint8_t { color, depth, ft, gripper };

enum class DeviceKind : std::uint8_t {
  v4l2,
  video,
  images,
  libcamera,
  openni2,
  oni,
  ati_can,
  robotous_can,
  ft300_rtu,
  ft300_tcp,
  robotiq_rtu,
  robotiq_tcp,
};

/// The Robotiq default Modbus slave (unit) ID, used when a spec gives none.
inline constexpr int kDefaultModbusSlave = 9;

struct DeviceSpec {
  DeviceRole role = DeviceRole::color;
  DeviceKind kind = DeviceKind::video;
  std::string text;  ///< the spec as given (for messages and recording.json)
  /// v4l2: "/dev/..." or the index digits; video, images, oni: the path or pattern; libcamera:
  /// the camera id ("" for any); openni2: the URI or "any"; CAN kinds: the interface; *-rtu:
  /// the serial device; *-tcp: the IPv4 host.
  std::string location;
  bool any = false;                     ///< libcamera:any, openni2:any
  std::uint32_t can_id = 0;             ///< ati-can: base ID; robotous-can: command ID
  std::uint32_t can_response_1 = 0x01;  ///< robotous-can
  std::uint32_t can_response_2 = 0x02;  ///< robotous-can
  int port = 0;                         ///< *-tcp
  int slave_id = kDefaultModbusSlave;   ///< Modbus kinds
};

class DeviceSpecError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Parses `text` given to the option of `role`. Throws DeviceSpecError (see the top).
DeviceSpec parse_device_spec(DeviceRole role, std::string_view text);

/// "--color", "--depth", "--ft", "--gripper".
const char* device_role_option(DeviceRole role) noexcept;
/// "color", "depth", "ft", "gripper" (keys in recording.json meta.devices).
const char* device_role_name(DeviceRole role) noexcept;
/// The KIND word of a spec ("v4l2", "ati-can", ...): the scheme its driver registers.
const char* device_kind_name(DeviceKind kind) noexcept;
/// The drivers/ folder that opens a kind ("opencv", "socketcan", ...), and the Debian package
/// that driver needs ("libopencv-dev", ...): what to install when a build lacks it.
const char* device_kind_driver(DeviceKind kind) noexcept;
const char* device_kind_package(DeviceKind kind) noexcept;
/// True for sources that play a file (video, images, oni): they end on their own.
bool is_file_backed(DeviceKind kind) noexcept;

}  // namespace pliant::cli
