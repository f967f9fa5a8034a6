// `pliant record` and the device registry (host/cli/record_devices.hpp, cli_registry.hpp): every
// kind of spec becomes a hal::DeviceSpec whose parameters its driver declared, the CLI's table of
// drivers agrees with what the drivers registered, and a kind whose driver this build lacks is
// refused with the package to install; the optional commands (track, track-depth) and the words
// for one a build lacks. Which drivers are built varies; the checks hold for any mix.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "cli_registry.hpp"
#include "exit_status.hpp"
#include "record_device_spec.hpp"
#include "record_devices.hpp"

namespace pliant::cli {
namespace {

struct Example {
  DeviceRole role;
  const char* text;
};

const Example kExamples[] = {
    {DeviceRole::color, "v4l2:/dev/video0"},
    {DeviceRole::color, "video:take1.avi"},
    {DeviceRole::color, "images:frames/f_%04d.png"},
    {DeviceRole::color, "libcamera:any"},
    {DeviceRole::depth, "openni2:any"},
    {DeviceRole::depth, "oni:take1.oni"},
    {DeviceRole::ft, "ati-can:can0@0x20"},
    {DeviceRole::ft, "robotous-can:can0@0x64,0x11,0x12"},
    {DeviceRole::ft, "ft300-rtu:/dev/ttyUSB1@7"},
    {DeviceRole::ft, "ft300-tcp:192.168.1.11:502"},
    {DeviceRole::gripper, "robotiq-rtu:/dev/ttyUSB0"},
    {DeviceRole::gripper, "robotiq-tcp:192.168.1.11:5020@3"},
};

TEST(CliRecordRegistry, SpecsBecomeTheSchemesTheDriversRegistered) {
  const hal::DeviceRegistry& registry = cli_registry().devices;
  DeviceOpenOptions options;
  options.tare = true;
  options.gripper_stroke_m = 0.14;
  int registered = 0;
  for (const Example& e : kExamples) {
    const DeviceSpec spec = parse_device_spec(e.role, e.text);
    const hal::DeviceSpec hal_spec = to_hal_spec(spec, options);
    EXPECT_EQ(hal_spec.scheme, device_kind_name(spec.kind));
    const hal::SchemeInfo* scheme = registry.find(device_category(e.role), hal_spec.scheme);
    if (scheme == nullptr) {
      try {
        check_driver_built(spec);
        ADD_FAILURE() << e.text << ": accepted without its driver";
      } catch (const UsageError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find(std::string("this pliant was built without drivers/") + device_kind_driver(spec.kind) +
                               "; install " + device_kind_package(spec.kind) + " and rebuild"),
                  std::string::npos)
            << message;
      }
      continue;
    }
    ++registered;
    EXPECT_NO_THROW(check_driver_built(spec)) << e.text;
    EXPECT_EQ(scheme->driver, device_kind_driver(spec.kind)) << e.text;  // the CLI's table agrees
    for (const auto& parameter : hal_spec.parameters) {
      EXPECT_NE(std::find(scheme->parameters.begin(), scheme->parameters.end(), parameter.first),
                scheme->parameters.end())
          << e.text << ": " << parameter.first;
    }
  }
  // Every scheme registered in the categories of `pliant record` is one the CLI parses.
  for (const hal::SchemeInfo& s : registry.schemes()) {
    bool parsed = false;
    for (const Example& e : kExamples)
      parsed = parsed || s.scheme == device_kind_name(parse_device_spec(e.role, e.text).kind);
    EXPECT_TRUE(parsed) << s.scheme;
  }
  EXPECT_EQ(static_cast<std::size_t>(registered), registry.schemes().size());
}

TEST(CliRecordRegistry, NumbersAndOptionsAsParameters) {
  DeviceOpenOptions options;
  options.tare = true;
  options.gripper_stroke_m = 0.14;
  hal::DeviceSpec s = to_hal_spec(parse_device_spec(DeviceRole::ft, "robotous-can:can0@0x64,0x11,0x12"), options);
  EXPECT_EQ(s.location, "can0");
  EXPECT_EQ(s.integer("command_id", 0, 0x7ff), 0x64);
  EXPECT_EQ(s.integer("response_1", 0, 0x7ff), 0x11);
  EXPECT_EQ(s.integer("response_2", 0, 0x7ff), 0x12);
  EXPECT_TRUE(s.flag("tare", false));
  s = to_hal_spec(parse_device_spec(DeviceRole::gripper, "robotiq-tcp:192.168.1.11:5020@3"), options);
  EXPECT_EQ(s.location, "192.168.1.11");
  EXPECT_EQ(s.integer("port", 1, 65535), 5020);
  EXPECT_EQ(s.integer("slave", 0, 247), 3);
  EXPECT_EQ(s.number("stroke_m", 0, 1, 0), 0.14);  // exactly the option's value
  EXPECT_FALSE(s.has("tare"));
  s = to_hal_spec(parse_device_spec(DeviceRole::color, "libcamera:any"), options);
  EXPECT_EQ(s.location, "any");
  EXPECT_EQ(s.text("format"), "bgr8");
  s = to_hal_spec(parse_device_spec(DeviceRole::depth, "oni:a.oni"), options);
  EXPECT_EQ(s.text("playback"), "real_time");
  s = to_hal_spec(parse_device_spec(DeviceRole::ft, "ati-can:can0@0x20"), DeviceOpenOptions());
  EXPECT_EQ(s.integer("base_id", 0, 0x7f), 0x20);
  EXPECT_FALSE(s.flag("tare", true));
}

TEST(CliRecordRegistry, OptionalCommandsAndTheWordsForOneLeftOut) {
  const CliRegistry empty;
  EXPECT_EQ(missing_command_message(empty, "track"), "this pliant was built without OpenCV: track is not available");
  EXPECT_EQ(missing_command_message(empty, "track-depth"),
            "this pliant was built without the depth front end (libpng, nanoflann): track-depth is not available");
  EXPECT_EQ(missing_command_message(empty, "estimate"), "");  // always built: not ours to explain
  EXPECT_EQ(missing_command_message(empty, "trac"), "");
  // This build: every command it registered is available, and each is a known optional one.
  for (const CommandPart& part : cli_registry().commands) {
    EXPECT_EQ(missing_command_message(cli_registry(), part.name), "") << part.name;
    EXPECT_TRUE(std::any_of(std::begin(kOptionalCommands), std::end(kOptionalCommands),
                            [&](const OptionalCommandNeed& need) { return need.name == part.name; }))
        << part.name;
  }
}

}  // namespace
}  // namespace pliant::cli
