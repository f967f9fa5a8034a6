// pliant hal: the device registry. Each driver registers factories that make one of its devices
// from a spec (scheme, location, parameters), and discoveries that list what it finds connected;
// host tools open devices and list them by asking the registry, so no tool names a driver or
// needs to know which drivers a build has (docs/hal.md, "Device registry").
//
//   hal::DeviceRegistry registry;
//   pliant::drivers::register_modbus_devices(registry);  // one call per driver that was built
//   hal::DeviceSpec spec;
//   spec.scheme = "robotiq-tcp";
//   spec.location = "192.168.1.11";
//   spec.parameters["port"] = "502";
//   hal::OpenResult opened = registry.open(hal::DeviceCategory::gripper, spec, clock);
//   if (!opened) report(opened.status, opened.error);   // one line, the driver's reason
//   hal::Gripper& gripper = *opened.device->gripper();   // configured: start() it, read it
//
// Factories: construct the device on the caller's clock (which must outlive it) and configure
// it. The device comes back inactive, owning whatever it needs (a CAN transport, ...); a failed
// configure comes back as its HalStatus and the driver's reason in words. A factory may throw
// std::invalid_argument for a malformed parameter (DeviceSpec's typed getters do); open() turns
// that into invalid_argument and any other exception into io_error: nothing escapes open().
// Parameters a scheme did not declare are refused before its factory runs.
//
// Host code: the registry and its factories allocate and may throw (only open() and discover()
// promise not to); never use them on a real-time path. The devices they make are as real-time
// safe as their drivers say. Thread safety: register from one thread before use; after that the
// const calls may run concurrently (what a factory touches is its driver's business).
#pragma once

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/device.hpp"
#include "pliant/hal/force_torque.hpp"
#include "pliant/hal/gripper.hpp"
#include "pliant/hal/status.hpp"

namespace pliant::hal {

/// The device categories a factory can make (one HAL interface each).
enum class DeviceCategory : std::uint8_t { color_camera, depth_camera, force_torque, gripper };

/// "colour camera", "depth camera", "force/torque sensor", "gripper" (for messages).
const char* device_category_name(DeviceCategory category) noexcept;

/// What to open: `scheme:location` plus named parameters, as text. The typed getters read a
/// parameter and throw std::invalid_argument with one line naming it when it is malformed.
struct DeviceSpec {
  std::string scheme;    ///< "v4l2", "oni", "ati-can", ... (the registered scheme)
  std::string location;  ///< what the scheme opens: a path, a URI, a CAN interface, an IPv4 host
  std::map<std::string, std::string, std::less<>> parameters;  ///< name -> value, as text

  bool has(std::string_view name) const;
  /// The value, or `fallback` when absent.
  std::string text(std::string_view name, std::string_view fallback = {}) const;
  /// An integer in [min, max], decimal or hexadecimal with 0x; `fallback` when absent.
  std::int64_t integer(std::string_view name, std::int64_t min, std::int64_t max, std::int64_t fallback) const;
  /// As above, but the parameter is required.
  std::int64_t integer(std::string_view name, std::int64_t min, std::int64_t max) const;
  /// A finite number in [min, max]; `fallback` when absent.
  double number(std::string_view name, double min, double max, double fallback) const;
  /// true/false, 1/0, yes/no, on/off; `fallback` when absent.
  bool flag(std::string_view name, bool fallback) const;
  /// One of `choices`; `fallback` when absent.
  std::string choice(std::string_view name, std::initializer_list<std::string_view> choices,
                     std::string_view fallback) const;
};

/// Driver counters and facts of an opened device, for logs and recording metadata: named values
/// in the order added. A '.' in a name nests it ("link.timeouts": `timeouts` of the `link`).
class DeviceInfo {
 public:
  using Value = std::variant<bool, std::int64_t, std::uint64_t, double, std::string>;
  struct Field {
    std::string name;
    Value value;
  };

  DeviceInfo& add(std::string name, bool value);
  DeviceInfo& add(std::string name, int value) { return add_signed(std::move(name), value); }
  DeviceInfo& add(std::string name, long value) { return add_signed(std::move(name), value); }
  DeviceInfo& add(std::string name, long long value) { return add_signed(std::move(name), value); }
  DeviceInfo& add(std::string name, unsigned value) { return add_unsigned(std::move(name), value); }
  DeviceInfo& add(std::string name, unsigned long value) { return add_unsigned(std::move(name), value); }
  DeviceInfo& add(std::string name, unsigned long long value) { return add_unsigned(std::move(name), value); }
  DeviceInfo& add(std::string name, double value);
  DeviceInfo& add(std::string name, std::string value);
  DeviceInfo& add(std::string name, const char* value) { return add(std::move(name), std::string(value)); }
  /// Every field of `other` under `prefix.`.
  DeviceInfo& nest(const std::string& prefix, const DeviceInfo& other);

  const std::vector<Field>& fields() const noexcept { return fields_; }

 private:
  DeviceInfo& add_signed(std::string name, long long value);
  DeviceInfo& add_unsigned(std::string name, unsigned long long value);
  std::vector<Field> fields_;
};

/// A device made by a factory, with what a host tool needs beyond its HAL interface. Exactly
/// one of color_camera() .. gripper() is non-null: the one of its category. Destroying it stops
/// and cleans up the device, whatever its state.
class OpenedDevice {
 public:
  virtual ~OpenedDevice() = default;
  OpenedDevice(const OpenedDevice&) = delete;
  OpenedDevice& operator=(const OpenedDevice&) = delete;

  /// The lifecycle and counters.
  virtual Device& device() noexcept = 0;
  virtual ColorCamera* color_camera() noexcept { return nullptr; }
  virtual DepthCamera* depth_camera() noexcept { return nullptr; }
  virtual ForceTorqueSensor* force_torque() noexcept { return nullptr; }
  virtual Gripper* gripper() noexcept { return nullptr; }

  /// device().start(), then what the spec asked for once streaming (e.g. a tare).
  HalStatus start() noexcept;
  /// File sources: true once everything was delivered or dropped. Live devices: false.
  virtual bool ended() const noexcept { return false; }
  /// The driver's last error in words ("" when it has none or keeps none).
  virtual std::string last_error() const { return std::string(); }
  /// Driver counters and facts (see DeviceInfo).
  virtual DeviceInfo info() const { return DeviceInfo(); }

 protected:
  OpenedDevice() = default;
  /// Called by start() after device().start() succeeded.
  virtual void on_started() noexcept {}
  /// For implementations' destructors: stops `device` when active, cleans it up when inactive.
  static void shut_down(Device& device) noexcept;
};

/// What open() returns: a configured (inactive) device, or why there is none.
struct OpenResult {
  std::unique_ptr<OpenedDevice> device;  ///< null on failure
  HalStatus status = HalStatus::ok;      ///< ok, or the failure (invalid_argument: the spec is wrong)
  std::string error;                     ///< one line: the driver's reason ("" when it gave none)
  std::string driver;                    ///< the driver of the scheme (set by DeviceRegistry::open)

  explicit operator bool() const noexcept { return device != nullptr; }
  static OpenResult success(std::unique_ptr<OpenedDevice> device);
  static OpenResult failure(HalStatus status, std::string error);
};

/// Makes and configures a device from a spec on a clock (see the top).
using DeviceFactory = std::function<OpenResult(const DeviceSpec& spec, const Clock& clock)>;

/// A registered scheme, as listed.
struct SchemeInfo {
  DeviceCategory category = DeviceCategory::color_camera;
  std::string scheme;                   ///< lower-case letters, digits and '-': "ati-can"
  std::string driver;                   ///< the driver that registered it: "socketcan" (drivers/socketcan)
  std::string location;                 ///< what the location names: "CAN interface (can0)"
  std::string description;              ///< one line
  std::vector<std::string> parameters;  ///< the parameters the factory reads (others are refused)
};

/// One device a discovery found.
struct DiscoveredDevice {
  std::string name;        ///< "Microsoft Kinect for Windows", or "unknown device"
  std::string kind;        ///< "depth camera", "USB-CAN adapter", "other"
  std::string id;          ///< the bus's id of the model ("045e:02ae")
  std::string location;    ///< where it sits ("001/004 1-2.3")
  std::string handled_by;  ///< the pliant driver that opens it, or "none"
  std::string detail;      ///< anything else worth showing
};

struct DiscoveryOptions {
  bool include_unknown = false;  ///< also list devices no pliant driver handles
};

/// What a discovery found. Never an error: an empty list and a note say why.
struct Discovery {
  std::vector<DiscoveredDevice> devices;
  std::vector<std::string> notes;  ///< why the list may be incomplete ("no USB in this container")
  std::string text;                ///< the same for people, as the driver lays it out ("" for none)
};

using DiscoveryFunction = std::function<Discovery(const DiscoveryOptions& options)>;

/// A registered discovery, as listed.
struct DiscoveryInfo {
  std::string name;         ///< "usb"
  std::string driver;       ///< "usb"
  std::string description;  ///< one line
};

class DeviceRegistry {
 public:
  /// Registers `factory` for `info.scheme` in `info.category`. Throws std::invalid_argument for
  /// an empty or malformed scheme, an empty driver, a null factory or a scheme already
  /// registered (in any category: a scheme names one kind of device).
  void add(SchemeInfo info, DeviceFactory factory);
  /// Registers a discovery under `info.name`. Throws std::invalid_argument for an empty name or
  /// driver, a null function or a name already registered.
  void add_discovery(DiscoveryInfo info, DiscoveryFunction function);

  /// The scheme in `category`, or null.
  const SchemeInfo* find(DeviceCategory category, std::string_view scheme) const;
  /// Every scheme, by category, then by name.
  std::vector<SchemeInfo> schemes() const;
  /// The schemes of `category`, by name.
  std::vector<SchemeInfo> schemes(DeviceCategory category) const;
  /// Every driver that registered a scheme or a discovery, sorted.
  std::vector<std::string> drivers() const;

  /// Opens `spec` as a device of `category` on `clock` (which must outlive the device). Never
  /// throws. Failures: unsupported for a scheme this registry does not have in `category` (the
  /// error names the schemes it has), invalid_argument for an undeclared or malformed
  /// parameter, else the factory's status and reason.
  OpenResult open(DeviceCategory category, const DeviceSpec& spec, const Clock& clock) const;
  /// The message open() gives for a scheme it does not have in `category`.
  std::string unknown_scheme_message(DeviceCategory category, std::string_view scheme) const;

  /// The discovery named `name`, or null.
  const DiscoveryInfo* find_discovery(std::string_view name) const;
  /// Every discovery, by name.
  std::vector<DiscoveryInfo> discoveries() const;
  /// Runs the discovery `name`. Never throws: an unknown name or a failure is a note.
  Discovery discover(std::string_view name, const DiscoveryOptions& options) const;

 private:
  struct Scheme {
    SchemeInfo info;
    DeviceFactory factory;
  };
  struct Discoverer {
    DiscoveryInfo info;
    DiscoveryFunction function;
  };
  std::vector<Scheme> schemes_;
  std::vector<Discoverer> discoverers_;
};

}  // namespace pliant::hal
