// `pliant record` device specs (host/cli/record_device_spec.hpp): every kind, the numbers, and
// malformed text, which must give one clear line naming the option and the expected form.
#include <gtest/gtest.h>

#include <string>

#include "record_device_spec.hpp"

namespace pliant::cli {
namespace {

// The message of the DeviceSpecError `text` raises for `role` (fails the test if none).
std::string error_of(DeviceRole role, const std::string& text) {
  try {
    (void)parse_device_spec(role, text);
  } catch (const DeviceSpecError& e) {
    return e.what();
  }
  ADD_FAILURE() << "'" << text << "' was accepted";
  return std::string();
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(RecordDeviceSpec, ColorKinds) {
  DeviceSpec s = parse_device_spec(DeviceRole::color, "v4l2:/dev/video0");
  EXPECT_EQ(s.kind, DeviceKind::v4l2);
  EXPECT_EQ(s.location, "/dev/video0");
  EXPECT_EQ(s.text, "v4l2:/dev/video0");
  EXPECT_EQ(s.role, DeviceRole::color);
  EXPECT_EQ(parse_device_spec(DeviceRole::color, "v4l2:2").location, "2");
  EXPECT_EQ(parse_device_spec(DeviceRole::color, "v4l2:/dev/v4l/by-id/usb-cam-video-index0").location,
            "/dev/v4l/by-id/usb-cam-video-index0");
  s = parse_device_spec(DeviceRole::color, "video:take 1:a.avi");  // everything after the first ':'
  EXPECT_EQ(s.kind, DeviceKind::video);
  EXPECT_EQ(s.location, "take 1:a.avi");
  EXPECT_TRUE(is_file_backed(s.kind));
  s = parse_device_spec(DeviceRole::color, "images:frames/f_%04d.png");
  EXPECT_EQ(s.kind, DeviceKind::images);
  EXPECT_EQ(s.location, "frames/f_%04d.png");
  s = parse_device_spec(DeviceRole::color, "libcamera:any");
  EXPECT_EQ(s.kind, DeviceKind::libcamera);
  EXPECT_TRUE(s.any);
  EXPECT_EQ(s.location, "");
  s = parse_device_spec(DeviceRole::color, "libcamera:/base/soc/i2c0mux/i2c@1/imx219@10");
  EXPECT_FALSE(s.any);
  EXPECT_EQ(s.location, "/base/soc/i2c0mux/i2c@1/imx219@10");
  EXPECT_FALSE(is_file_backed(DeviceKind::v4l2));
  EXPECT_FALSE(is_file_backed(DeviceKind::libcamera));
}

TEST(RecordDeviceSpec, DepthKinds) {
  DeviceSpec s = parse_device_spec(DeviceRole::depth, "openni2:any");
  EXPECT_EQ(s.kind, DeviceKind::openni2);
  EXPECT_TRUE(s.any);
  EXPECT_EQ(s.location, "any");
  s = parse_device_spec(DeviceRole::depth, "openni2:1d27/0601@1/5");
  EXPECT_FALSE(s.any);
  EXPECT_EQ(s.location, "1d27/0601@1/5");
  s = parse_device_spec(DeviceRole::depth, "oni:rec/room.oni");
  EXPECT_EQ(s.kind, DeviceKind::oni);
  EXPECT_EQ(s.location, "rec/room.oni");
  EXPECT_TRUE(is_file_backed(s.kind));
}

TEST(RecordDeviceSpec, CanSensors) {
  DeviceSpec s = parse_device_spec(DeviceRole::ft, "ati-can:can0@0x20");
  EXPECT_EQ(s.kind, DeviceKind::ati_can);
  EXPECT_EQ(s.location, "can0");
  EXPECT_EQ(s.can_id, 0x20u);
  EXPECT_EQ(parse_device_spec(DeviceRole::ft, "ati-can:vcan1@0X7F").can_id, 0x7fu);
  EXPECT_EQ(parse_device_spec(DeviceRole::ft, "ati-can:can0@32").can_id, 32u);
  s = parse_device_spec(DeviceRole::ft, "robotous-can:can1@0x64");
  EXPECT_EQ(s.kind, DeviceKind::robotous_can);
  EXPECT_EQ(s.location, "can1");
  EXPECT_EQ(s.can_id, 0x64u);
  EXPECT_EQ(s.can_response_1, 0x01u);
  EXPECT_EQ(s.can_response_2, 0x02u);
  s = parse_device_spec(DeviceRole::ft, "robotous-can:can0@0xF0,0xF1,0xF2");
  EXPECT_EQ(s.can_id, 0xf0u);
  EXPECT_EQ(s.can_response_1, 0xf1u);
  EXPECT_EQ(s.can_response_2, 0xf2u);
  EXPECT_EQ(parse_device_spec(DeviceRole::ft, "ati-can:abcdefghijklmno@1").location, "abcdefghijklmno");  // 15
}

TEST(RecordDeviceSpec, ModbusDevices) {
  DeviceSpec s = parse_device_spec(DeviceRole::ft, "ft300-rtu:/dev/ttyUSB1");
  EXPECT_EQ(s.kind, DeviceKind::ft300_rtu);
  EXPECT_EQ(s.location, "/dev/ttyUSB1");
  EXPECT_EQ(s.slave_id, kDefaultModbusSlave);
  s = parse_device_spec(DeviceRole::ft, "ft300-tcp:192.168.1.11:502");
  EXPECT_EQ(s.kind, DeviceKind::ft300_tcp);
  EXPECT_EQ(s.location, "192.168.1.11");
  EXPECT_EQ(s.port, 502);
  s = parse_device_spec(DeviceRole::gripper, "robotiq-rtu:/dev/ttyUSB0@7");
  EXPECT_EQ(s.kind, DeviceKind::robotiq_rtu);
  EXPECT_EQ(s.location, "/dev/ttyUSB0");
  EXPECT_EQ(s.slave_id, 7);
  s = parse_device_spec(DeviceRole::gripper, "robotiq-tcp:127.0.0.1:65535@0");
  EXPECT_EQ(s.kind, DeviceKind::robotiq_tcp);
  EXPECT_EQ(s.location, "127.0.0.1");
  EXPECT_EQ(s.port, 65535);
  EXPECT_EQ(s.slave_id, 0);
  EXPECT_EQ(parse_device_spec(DeviceRole::gripper, "robotiq-rtu:/dev/ttyUSB0@247").slave_id, 247);
}

TEST(RecordDeviceSpec, NamesOfRolesAndKinds) {
  EXPECT_STREQ(device_role_option(DeviceRole::gripper), "--gripper");
  EXPECT_STREQ(device_role_name(DeviceRole::ft), "ft");
  EXPECT_STREQ(device_kind_name(DeviceKind::robotous_can), "robotous-can");
  EXPECT_STREQ(device_kind_name(DeviceKind::ft300_tcp), "ft300-tcp");
}

TEST(RecordDeviceSpec, MissingKindOrLocation) {
  std::string m = error_of(DeviceRole::ft, "can0");
  EXPECT_TRUE(contains(m, "--ft 'can0': expected KIND:LOCATION")) << m;
  EXPECT_TRUE(contains(m, "ati-can, robotous-can, ft300-rtu, ft300-tcp")) << m;
  m = error_of(DeviceRole::color, "video:");
  EXPECT_TRUE(contains(m, "nothing after 'video:'")) << m;
  EXPECT_TRUE(contains(m, "expected video:FILE")) << m;
  m = error_of(DeviceRole::color, "");
  EXPECT_TRUE(contains(m, "--color '': expected KIND:LOCATION")) << m;
  m = error_of(DeviceRole::gripper, ":x");
  EXPECT_TRUE(contains(m, "unknown kind ''")) << m;
}

TEST(RecordDeviceSpec, UnknownKindOrWrongOption) {
  std::string m = error_of(DeviceRole::color, "webcam:0");
  EXPECT_TRUE(contains(m, "unknown kind 'webcam'; --color takes v4l2, video, images, libcamera")) << m;
  m = error_of(DeviceRole::color, "openni2:any");
  EXPECT_TRUE(contains(m, "'openni2' is a --depth device; --color takes")) << m;
  m = error_of(DeviceRole::gripper, "ft300-tcp:127.0.0.1:502");
  EXPECT_TRUE(contains(m, "'ft300-tcp' is a --ft device")) << m;
  m = error_of(DeviceRole::ft, "V4L2:0");  // kinds are case-sensitive
  EXPECT_TRUE(contains(m, "unknown kind")) << m;
}

TEST(RecordDeviceSpec, BadV4l2) {
  EXPECT_TRUE(contains(error_of(DeviceRole::color, "v4l2:video0"), "expected v4l2:/dev/videoN or v4l2:N"));
  EXPECT_TRUE(contains(error_of(DeviceRole::color, "v4l2:/dev/"), "expected v4l2:"));
  EXPECT_TRUE(contains(error_of(DeviceRole::color, "v4l2:12345"), "device index too large"));
  EXPECT_TRUE(contains(error_of(DeviceRole::color, "v4l2:-1"), "expected v4l2:"));
}

TEST(RecordDeviceSpec, BadCanSpecs) {
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "ati-can:can0"), "no base ID"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "ati-can:@0x20"), "no interface name"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "ati-can:can0@0x80"), "base ID must be 0..0x7f"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "ati-can:can0@0x"), "base ID must be"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "ati-can:can0@0xg1"), "base ID must be"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "ati-can:can0@-1"), "base ID must be"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "ati-can:can0@0x000000020"), "base ID must be"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "ati-can:abcdefghijklmnop@1"), "longer than 15"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "ati-can:can/0@1"), "bad interface name"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "ati-can:can 0@1"), "bad interface name"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "robotous-can:can0@0x800"), "standard IDs 0..0x7ff"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "robotous-can:can0@0x64,0x01"), "alone or with both"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "robotous-can:can0@0x64,0x01,0x01"), "must differ"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "robotous-can:can0@0x01"), "must differ"));  // = default response
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "robotous-can:can0@0x64,,0x2"), "standard IDs"));
}

TEST(RecordDeviceSpec, BadModbusSpecs) {
  std::string m = error_of(DeviceRole::gripper, "robotiq-tcp:localhost:502");
  EXPECT_TRUE(contains(m, "HOST must be a dotted IPv4 address")) << m;
  EXPECT_TRUE(contains(m, "expected robotiq-tcp:HOST:PORT[@SLAVE]")) << m;
  EXPECT_TRUE(contains(error_of(DeviceRole::gripper, "robotiq-tcp:127.0.0.1"), "no port"));
  EXPECT_TRUE(contains(error_of(DeviceRole::gripper, "robotiq-tcp:127.0.0.1:0"), "PORT must be 1..65535"));
  EXPECT_TRUE(contains(error_of(DeviceRole::gripper, "robotiq-tcp:127.0.0.1:65536"), "PORT must be"));
  EXPECT_TRUE(contains(error_of(DeviceRole::gripper, "robotiq-tcp:127.0.0.1:"), "PORT must be"));
  EXPECT_TRUE(contains(error_of(DeviceRole::gripper, "robotiq-tcp:127.0.0.256:502"), "dotted IPv4"));
  EXPECT_TRUE(contains(error_of(DeviceRole::gripper, "robotiq-tcp:127.0.0:502"), "dotted IPv4"));
  EXPECT_TRUE(contains(error_of(DeviceRole::gripper, "robotiq-tcp:127..0.1:502"), "dotted IPv4"));
  EXPECT_TRUE(contains(error_of(DeviceRole::gripper, "robotiq-tcp:1.2.3.4.5:502"), "dotted IPv4"));
  EXPECT_TRUE(contains(error_of(DeviceRole::gripper, "robotiq-rtu:/dev/ttyUSB0@248"), "SLAVE must be"));
  EXPECT_TRUE(contains(error_of(DeviceRole::gripper, "robotiq-rtu:/dev/ttyUSB0@"), "SLAVE must be"));
  EXPECT_TRUE(contains(error_of(DeviceRole::gripper, "robotiq-rtu:/dev/ttyUSB0@x"), "SLAVE must be"));
  EXPECT_TRUE(contains(error_of(DeviceRole::gripper, "robotiq-rtu:@9"), "no serial device"));
  EXPECT_TRUE(contains(error_of(DeviceRole::ft, "ft300-tcp:10.0.0.1:502@99999999999"), "SLAVE must be"));
}

TEST(RecordDeviceSpec, ControlCharactersAndLength) {
  std::string m = error_of(DeviceRole::color, std::string("video:a\nb.avi"));
  EXPECT_TRUE(contains(m, "contains a control character")) << m;
  EXPECT_TRUE(contains(m, "\\x0a")) << m;  // escaped in the message, which stays one line
  EXPECT_EQ(m.find('\n'), std::string::npos);
  m = error_of(DeviceRole::color, std::string("video:a\0b", 9));
  EXPECT_TRUE(contains(m, "control character")) << m;
  m = error_of(DeviceRole::color, "video:" + std::string(5000, 'a'));
  EXPECT_TRUE(contains(m, "longer than 4096")) << m;
  EXPECT_LT(m.size(), 300u);  // the spec is cut in the message
  m = error_of(DeviceRole::color, "\xff\xfe:x");
  EXPECT_TRUE(contains(m, "\\xff\\xfe")) << m;
}

}  // namespace
}  // namespace pliant::cli
