// The device registry (hal/device_registry.hpp): registration and its refusals, lookup and
// listing, opening through a factory (configured device, driver name, start hook, teardown),
// clear errors for unknown schemes and bad parameters, the typed parameter getters, DeviceInfo
// and discoveries.
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "pliant/hal/device_registry.hpp"

namespace pliant::hal {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// What a test device did, kept outside it so that it can be checked after the device is gone.
struct Trace {
  int configures = 0, starts = 0, stops = 0, cleanups = 0, started_hooks = 0;
};

class TestSensor final : public ForceTorqueSensor {
 public:
  TestSensor(Trace& trace, HalStatus configure_result) : trace_(trace), configure_result_(configure_result) {}

 protected:
  HalStatus on_configure() override {
    ++trace_.configures;
    return configure_result_;
  }
  HalStatus on_start() noexcept override {
    ++trace_.starts;
    return HalStatus::ok;
  }
  HalStatus on_stop() noexcept override {
    ++trace_.stops;
    return HalStatus::ok;
  }
  HalStatus on_cleanup() noexcept override {
    ++trace_.cleanups;
    return HalStatus::ok;
  }
  HalStatus on_read(WrenchReading&) noexcept override { return HalStatus::no_data; }

 private:
  Trace& trace_;
  HalStatus configure_result_;
};

class OpenedTestSensor final : public OpenedDevice {
 public:
  OpenedTestSensor(Trace& trace, HalStatus configure_result, std::int64_t id)
      : trace_(trace), sensor_(trace, configure_result), id_(id) {}
  ~OpenedTestSensor() override { shut_down(sensor_); }
  Device& device() noexcept override { return sensor_; }
  ForceTorqueSensor* force_torque() noexcept override { return &sensor_; }
  std::string last_error() const override { return "the test sensor says no"; }
  DeviceInfo info() const override {
    DeviceInfo link;
    link.add("timeouts", std::uint64_t{3});
    DeviceInfo info;
    info.add("id", id_).add("ready", true).nest("link", link);
    return info;
  }

 protected:
  void on_started() noexcept override { ++trace_.started_hooks; }

 private:
  Trace& trace_;
  TestSensor sensor_;
  std::int64_t id_;
};

// A factory for "test-ft": parameter id (required, 0..0x7f), fail (configure result).
DeviceFactory test_factory(Trace& trace) {
  return [&trace](const DeviceSpec& spec, const Clock&) {
    const std::int64_t id = spec.integer("id", 0, 0x7f);
    const HalStatus result = spec.flag("fail", false) ? HalStatus::disconnected : HalStatus::ok;
    auto opened = std::make_unique<OpenedTestSensor>(trace, result, id);
    const HalStatus status = opened->device().configure();
    if (status != HalStatus::ok) return OpenResult::failure(status, opened->last_error());
    return OpenResult::success(std::move(opened));
  };
}

DeviceFactory never_called() {
  return [](const DeviceSpec&, const Clock&) -> OpenResult {
    ADD_FAILURE() << "factory called";
    return OpenResult::failure(HalStatus::io_error, "called");
  };
}

DeviceSpec spec_of(std::string scheme, std::string location = "here") {
  DeviceSpec s;
  s.scheme = std::move(scheme);
  s.location = std::move(location);
  return s;
}

TEST(HalDeviceRegistry, RegistersLooksUpAndLists) {
  Trace trace;
  DeviceRegistry registry;
  EXPECT_TRUE(registry.schemes().empty());
  EXPECT_TRUE(registry.drivers().empty());
  registry.add({DeviceCategory::gripper, "grip-b", "beta", "a port", "a gripper", {}}, never_called());
  registry.add({DeviceCategory::force_torque, "test-ft", "alpha", "a bus", "a sensor", {"id", "fail"}},
               test_factory(trace));
  registry.add({DeviceCategory::color_camera, "cam", "alpha", "a file", "a camera", {}}, never_called());
  registry.add({DeviceCategory::gripper, "grip-a", "beta", "a port", "another gripper", {}}, never_called());

  const SchemeInfo* found = registry.find(DeviceCategory::force_torque, "test-ft");
  ASSERT_NE(found, nullptr);
  EXPECT_EQ(found->driver, "alpha");
  EXPECT_EQ(found->parameters, (std::vector<std::string>{"id", "fail"}));
  EXPECT_EQ(registry.find(DeviceCategory::gripper, "test-ft"), nullptr);  // another category
  EXPECT_EQ(registry.find(DeviceCategory::force_torque, "nope"), nullptr);

  // By category (in enum order), then by name.
  std::vector<std::string> order;
  for (const SchemeInfo& s : registry.schemes()) order.push_back(s.scheme);
  EXPECT_EQ(order, (std::vector<std::string>{"cam", "test-ft", "grip-a", "grip-b"}));
  const std::vector<SchemeInfo> grippers = registry.schemes(DeviceCategory::gripper);
  ASSERT_EQ(grippers.size(), 2u);
  EXPECT_EQ(grippers[0].scheme, "grip-a");
  EXPECT_TRUE(registry.schemes(DeviceCategory::depth_camera).empty());
  EXPECT_EQ(registry.drivers(), (std::vector<std::string>{"alpha", "beta"}));
  EXPECT_STREQ(device_category_name(DeviceCategory::force_torque), "force/torque sensor");
}

TEST(HalDeviceRegistry, RefusesBadRegistrations) {
  DeviceRegistry registry;
  registry.add({DeviceCategory::depth_camera, "oni", "d", "", "", {}}, never_called());
  EXPECT_THROW(registry.add({DeviceCategory::depth_camera, "oni", "e", "", "", {}}, never_called()),
               std::invalid_argument);
  EXPECT_THROW(registry.add({DeviceCategory::color_camera, "oni", "e", "", "", {}}, never_called()),
               std::invalid_argument);  // one scheme, one kind of device
  for (const char* bad : {"", "Oni", "o n", "a:b", "x_y"}) {
    EXPECT_THROW(registry.add({DeviceCategory::color_camera, bad, "d", "", "", {}}, never_called()),
                 std::invalid_argument)
        << bad;
  }
  EXPECT_THROW(registry.add({DeviceCategory::color_camera, "cam", "", "", "", {}}, never_called()),
               std::invalid_argument);
  EXPECT_THROW(registry.add({DeviceCategory::color_camera, "cam", "d", "", "", {}}, DeviceFactory()),
               std::invalid_argument);
  EXPECT_EQ(registry.schemes().size(), 1u);
  try {
    registry.add({DeviceCategory::depth_camera, "oni", "other", "", "", {}}, never_called());
    ADD_FAILURE() << "registered twice";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(contains(e.what(), "'oni' registered twice (drivers d and other)")) << e.what();
  }
}

TEST(HalDeviceRegistry, OpensConfiguredDevicesThatShutDownWhenDestroyed) {
  Trace trace;
  DeviceRegistry registry;
  registry.add({DeviceCategory::force_torque, "test-ft", "alpha", "a bus", "a sensor", {"id", "fail"}},
               test_factory(trace));
  ManualClock clock;
  DeviceSpec spec = spec_of("test-ft");
  spec.parameters["id"] = "0x20";
  {
    OpenResult opened = registry.open(DeviceCategory::force_torque, spec, clock);
    ASSERT_TRUE(opened) << opened.error;
    EXPECT_EQ(opened.status, HalStatus::ok);
    EXPECT_EQ(opened.driver, "alpha");
    OpenedDevice& d = *opened.device;
    EXPECT_EQ(d.device().state(), LifecycleState::inactive);
    EXPECT_NE(d.force_torque(), nullptr);
    EXPECT_EQ(d.gripper(), nullptr);
    EXPECT_EQ(d.color_camera(), nullptr);
    EXPECT_EQ(d.depth_camera(), nullptr);
    EXPECT_FALSE(d.ended());
    EXPECT_EQ(d.start(), HalStatus::ok);
    EXPECT_EQ(trace.started_hooks, 1);
    EXPECT_EQ(d.start(), HalStatus::wrong_state);  // no hook after a refused start
    EXPECT_EQ(trace.started_hooks, 1);
    const DeviceInfo info = d.info();
    const std::vector<DeviceInfo::Field>& fields = info.fields();
    ASSERT_EQ(fields.size(), 3u);
    EXPECT_EQ(fields[0].name, "id");
    EXPECT_EQ(std::get<std::int64_t>(fields[0].value), 0x20);
    EXPECT_EQ(fields[2].name, "link.timeouts");
    EXPECT_EQ(std::get<std::uint64_t>(fields[2].value), 3u);
  }
  EXPECT_EQ(trace.configures, 1);
  EXPECT_EQ(trace.starts, 1);
  EXPECT_EQ(trace.stops, 1);  // destroyed while active: stopped, then cleaned up
  EXPECT_EQ(trace.cleanups, 1);
}

TEST(HalDeviceRegistry, UnknownSchemesAndBadParametersAreClearErrors) {
  Trace trace;
  DeviceRegistry registry;
  ManualClock clock;
  OpenResult none = registry.open(DeviceCategory::gripper, spec_of("robotiq-tcp"), clock);
  EXPECT_FALSE(none);
  EXPECT_EQ(none.status, HalStatus::unsupported);
  EXPECT_EQ(none.error, "no gripper driver for 'robotiq-tcp' in this build (none is built)");

  registry.add({DeviceCategory::force_torque, "test-ft", "alpha", "a bus", "a sensor", {"id", "fail"}},
               test_factory(trace));
  registry.add({DeviceCategory::force_torque, "other-ft", "beta", "a bus", "a sensor", {}}, never_called());
  OpenResult unknown = registry.open(DeviceCategory::force_torque, spec_of("ati-can"), clock);
  EXPECT_EQ(unknown.status, HalStatus::unsupported);
  EXPECT_EQ(unknown.error, "no force/torque sensor driver for 'ati-can' in this build (it has other-ft, test-ft)");
  EXPECT_EQ(unknown.error, registry.unknown_scheme_message(DeviceCategory::force_torque, "ati-can"));
  OpenResult wrong_category = registry.open(DeviceCategory::gripper, spec_of("test-ft"), clock);
  EXPECT_EQ(wrong_category.status, HalStatus::unsupported);
  EXPECT_EQ(wrong_category.error, "'test-ft' is a force/torque sensor, not a gripper");

  DeviceSpec spec = spec_of("test-ft");
  spec.parameters["id"] = "5";
  spec.parameters["speed"] = "9";  // not declared: refused before the factory runs
  OpenResult undeclared = registry.open(DeviceCategory::force_torque, spec, clock);
  EXPECT_EQ(undeclared.status, HalStatus::invalid_argument);
  EXPECT_EQ(undeclared.error, "test-ft has no parameter 'speed' (it takes id, fail)");
  EXPECT_EQ(trace.configures, 0);

  spec.parameters.erase("speed");
  spec.parameters["id"] = "0x80";
  OpenResult out_of_range = registry.open(DeviceCategory::force_torque, spec, clock);
  EXPECT_EQ(out_of_range.status, HalStatus::invalid_argument);
  EXPECT_EQ(out_of_range.error, "parameter 'id' = '0x80': expected an integer 0..127");
  spec.parameters.erase("id");
  OpenResult missing = registry.open(DeviceCategory::force_torque, spec, clock);
  EXPECT_EQ(missing.status, HalStatus::invalid_argument);
  EXPECT_EQ(missing.error, "parameter 'id' missing: expected an integer 0..127");

  // A configure that fails comes back with its status and the driver's reason.
  spec.parameters["id"] = "1";
  spec.parameters["fail"] = "yes";
  OpenResult refused = registry.open(DeviceCategory::force_torque, spec, clock);
  EXPECT_FALSE(refused);
  EXPECT_EQ(refused.status, HalStatus::disconnected);
  EXPECT_EQ(refused.error, "the test sensor says no");
  EXPECT_EQ(refused.driver, "alpha");

  // Nothing escapes open(): any other exception is an io_error with its text.
  registry.add({DeviceCategory::gripper, "throws", "gamma", "", "", {}},
               [](const DeviceSpec&, const Clock&) -> OpenResult { throw std::runtime_error("bus exploded"); });
  OpenResult thrown = registry.open(DeviceCategory::gripper, spec_of("throws"), clock);
  EXPECT_EQ(thrown.status, HalStatus::io_error);
  EXPECT_EQ(thrown.error, "bus exploded");
  registry.add({DeviceCategory::gripper, "empty", "gamma", "", "", {}},
               [](const DeviceSpec&, const Clock&) { return OpenResult(); });
  EXPECT_EQ(registry.open(DeviceCategory::gripper, spec_of("empty"), clock).status, HalStatus::io_error);
}

TEST(HalDeviceRegistry, TypedParameters) {
  DeviceSpec s;
  s.parameters = {{"dec", "42"},   {"hex", "0x7F"}, {"neg", "-3"}, {"junk", "4x"}, {"blank", ""},
                  {"num", "0.14"}, {"inf", "inf"},  {"yes", "on"}, {"no", "0"},    {"word", "stepped"}};
  EXPECT_TRUE(s.has("dec"));
  EXPECT_FALSE(s.has("absent"));
  EXPECT_EQ(s.text("word"), "stepped");
  EXPECT_EQ(s.text("absent", "dflt"), "dflt");
  EXPECT_EQ(s.integer("dec", 0, 100, 7), 42);
  EXPECT_EQ(s.integer("hex", 0, 0x7ff, 7), 0x7f);
  EXPECT_EQ(s.integer("neg", -5, 5, 7), -3);
  EXPECT_EQ(s.integer("absent", 0, 1, 7), 7);
  EXPECT_THROW((void)s.integer("dec", 0, 41, 7), std::invalid_argument);
  EXPECT_THROW((void)s.integer("junk", 0, 100, 7), std::invalid_argument);
  EXPECT_THROW((void)s.integer("blank", 0, 100, 7), std::invalid_argument);
  EXPECT_THROW((void)s.integer("absent", 0, 1), std::invalid_argument);
  EXPECT_DOUBLE_EQ(s.number("num", 0.001, 1.0, 0.085), 0.14);
  EXPECT_DOUBLE_EQ(s.number("absent", 0.001, 1.0, 0.085), 0.085);
  EXPECT_THROW((void)s.number("inf", 0, 1e300, 1), std::invalid_argument);
  EXPECT_THROW((void)s.number("dec", 0, 1, 1), std::invalid_argument);
  EXPECT_THROW((void)s.number("junk", 0, 100, 1), std::invalid_argument);
  EXPECT_TRUE(s.flag("yes", false));
  EXPECT_FALSE(s.flag("no", true));
  EXPECT_TRUE(s.flag("absent", true));
  EXPECT_THROW((void)s.flag("word", false), std::invalid_argument);
  EXPECT_EQ(s.choice("word", {"real_time", "stepped"}, "real_time"), "stepped");
  EXPECT_EQ(s.choice("absent", {"real_time", "stepped"}, "real_time"), "real_time");
  try {
    (void)s.choice("dec", {"real_time", "stepped"}, "real_time");
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "parameter 'dec' = '42': expected one of real_time, stepped");
  }
  s.parameters["ctl"] = std::string("a\x01") + std::string(100, 'b');  // shown escaped and cut
  try {
    (void)s.integer("ctl", 0, 1, 0);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    EXPECT_TRUE(contains(message, "'a?bbb")) << message;
    EXPECT_TRUE(contains(message, "...'")) << message;
    EXPECT_LT(message.size(), 120u);
  }
}

TEST(HalDeviceRegistry, DeviceInfoKeepsTypesAndOrder) {
  DeviceInfo inner;
  inner.add("frames", std::uint64_t{7});
  DeviceInfo info;
  info.add("flag", false).add("count", 3).add("big", std::uint64_t{1} << 40).add("scale", 0.5).add("name", "x");
  info.nest("link", inner);
  const auto& f = info.fields();
  ASSERT_EQ(f.size(), 6u);
  EXPECT_FALSE(std::get<bool>(f[0].value));
  EXPECT_EQ(std::get<std::int64_t>(f[1].value), 3);
  EXPECT_EQ(std::get<std::uint64_t>(f[2].value), std::uint64_t{1} << 40);
  EXPECT_EQ(std::get<double>(f[3].value), 0.5);
  EXPECT_EQ(std::get<std::string>(f[4].value), "x");
  EXPECT_EQ(f[5].name, "link.frames");
}

TEST(HalDeviceRegistry, Discoveries) {
  DeviceRegistry registry;
  EXPECT_EQ(registry.find_discovery("usb"), nullptr);
  const Discovery nothing = registry.discover("usb", {});
  EXPECT_TRUE(nothing.devices.empty());
  ASSERT_EQ(nothing.notes.size(), 1u);
  EXPECT_EQ(nothing.notes[0], "no discovery 'usb' in this build");

  registry.add_discovery({"usb", "usb", "USB devices"}, [](const DiscoveryOptions& options) {
    Discovery d;
    d.devices.push_back({"Camera", "depth camera", "1d27:0601", "001/004 1-2", "openni2", ""});
    if (options.include_unknown)
      d.devices.push_back({"unknown device", "other", "1234:5678", "001/005 1-3", "none", ""});
    d.text = "a table\n";
    return d;
  });
  registry.add_discovery({"flaky", "other", "throws"},
                         [](const DiscoveryOptions&) -> Discovery { throw std::runtime_error("no bus"); });
  EXPECT_THROW(registry.add_discovery({"usb", "usb", ""}, [](const DiscoveryOptions&) { return Discovery(); }),
               std::invalid_argument);
  EXPECT_THROW(registry.add_discovery({"", "usb", ""}, [](const DiscoveryOptions&) { return Discovery(); }),
               std::invalid_argument);
  EXPECT_THROW(registry.add_discovery({"x", "usb", ""}, DiscoveryFunction()), std::invalid_argument);

  ASSERT_NE(registry.find_discovery("usb"), nullptr);
  EXPECT_EQ(registry.find_discovery("usb")->driver, "usb");
  ASSERT_EQ(registry.discoveries().size(), 2u);
  EXPECT_EQ(registry.discoveries()[0].name, "flaky");
  EXPECT_EQ(registry.drivers(), (std::vector<std::string>{"other", "usb"}));
  EXPECT_EQ(registry.discover("usb", {}).devices.size(), 1u);
  DiscoveryOptions all;
  all.include_unknown = true;
  const Discovery found = registry.discover("usb", all);
  ASSERT_EQ(found.devices.size(), 2u);
  EXPECT_EQ(found.devices[0].handled_by, "openni2");
  EXPECT_EQ(found.text, "a table\n");
  const Discovery failed = registry.discover("flaky", {});
  ASSERT_EQ(failed.notes.size(), 1u);
  EXPECT_EQ(failed.notes[0], "flaky discovery failed: no bus");
}

}  // namespace
}  // namespace pliant::hal
