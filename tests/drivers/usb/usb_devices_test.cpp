// drivers/usb usb_sysfs and usb_devices: sysfs details read from a tree built here (strings,
// the canN interface of a CAN adapter, damaged attribute files), the rows and the text table of
// `pliant devices`.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "pliant/drivers/usb/usb_devices.hpp"
#include "pliant/drivers/usb/usb_sysfs.hpp"
#include "support/temp_dir.hpp"

namespace {

using namespace pliant::drivers::usb;
namespace fs = std::filesystem;

UsbDeviceInfo device(std::uint8_t bus, std::uint8_t address, std::vector<std::uint8_t> ports, std::uint16_t vid,
                     std::uint16_t pid) {
  UsbDeviceInfo d;
  d.key.bus = bus;
  d.key.address = address;
  d.key.port_count = static_cast<std::uint8_t>(ports.size());
  for (std::size_t i = 0; i < ports.size(); ++i) d.key.ports[i] = ports[i];
  d.vendor_id = vid;
  d.product_id = pid;
  return d;
}

void write(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary) << text;
}

// A sysfs tree with a PCAN-USB at 1-2 (interface can0) and a Kinect at 1-3.1.
struct FakeSysfs {
  pliant::test_support::TempDir dir{"pliant_sysfs_"};
  FakeSysfs() {
    const fs::path devices = dir.path() / "bus" / "usb" / "devices";
    write(devices / "1-2" / "manufacturer", "PEAK-System Technik GmbH\n");
    write(devices / "1-2" / "product", "PCAN-USB\n");
    write(devices / "1-2" / "serial", "0042\n");
    fs::create_directories(devices / "1-2:1.0" / "net" / "can0");
    write(devices / "1-3.1" / "product", std::string("Xbox NUI Camera\x01\xff\ntrailing", 26));
    fs::create_directories(devices / "1-3.1:1.0");                   // an interface without a netdev
    fs::create_directories(devices / "1-2.5:1.0" / "net" / "can9");  // another device's interface
  }
  std::string root() const { return dir.path().string(); }
};

TEST(UsbSysfs, ReadsStringsAndInterfaces) {
  const FakeSysfs sysfs;
  const UsbSysfsInfo pcan = read_usb_sysfs(sysfs.root(), device(1, 7, {2}, 0x0c72, 0x000c).key);
  EXPECT_TRUE(pcan.found);
  EXPECT_EQ(pcan.manufacturer, "PEAK-System Technik GmbH");
  EXPECT_EQ(pcan.product, "PCAN-USB");
  EXPECT_EQ(pcan.serial, "0042");
  EXPECT_EQ(pcan.net_interfaces, std::vector<std::string>{"can0"});

  const UsbSysfsInfo kinect = read_usb_sysfs(sysfs.root(), device(1, 8, {3, 1}, 0x045e, 0x02ae).key);
  EXPECT_TRUE(kinect.found);
  EXPECT_EQ(kinect.product, "Xbox NUI Camera??") << "non-printable bytes replaced, cut at the line break";
  EXPECT_TRUE(kinect.serial.empty());
  EXPECT_TRUE(kinect.net_interfaces.empty());

  const UsbSysfsInfo missing = read_usb_sysfs(sysfs.root(), device(4, 2, {1}, 0, 0).key);
  EXPECT_FALSE(missing.found);
  EXPECT_FALSE(read_usb_sysfs("/nonexistent/sys", device(1, 7, {2}, 0, 0).key).found);
}

TEST(UsbDevices, RowsForKnownDevices) {
  const FakeSysfs sysfs;
  UsbRowOptions options;
  options.sysfs_root = sysfs.root();
  const std::vector<UsbDeviceInfo> devices = {device(1, 7, {2}, 0x0c72, 0x000c), device(1, 8, {3, 1}, 0x045e, 0x02ae),
                                              device(1, 1, {}, 0x1d6b, 0x0002)};  // a root hub: unknown
  const std::vector<UsbDeviceRow> rows = describe_usb_devices(devices, options);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].name, "PEAK PCAN-USB");
  EXPECT_EQ(rows[0].kind, "can_adapter");
  EXPECT_EQ(rows[0].id, "0c72:000c");
  EXPECT_EQ(rows[0].location, "001/007 1-2");
  EXPECT_EQ(rows[0].handled_by, "socketcan");
  EXPECT_NE(rows[0].detail.find("interface can0"), std::string::npos) << rows[0].detail;
  EXPECT_NE(rows[0].detail.find("serial 0042"), std::string::npos) << rows[0].detail;
  EXPECT_NE(rows[0].detail.find("peak_usb"), std::string::npos) << rows[0].detail;
  EXPECT_EQ(rows[1].id, "045e:02ae");
  EXPECT_EQ(rows[1].handled_by, "openni2");
  EXPECT_EQ(rows[1].location, "001/008 1-3.1");

  options.include_unknown = true;
  const std::vector<UsbDeviceRow> all = describe_usb_devices(devices, options);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[2].name, "unknown device");
  EXPECT_EQ(all[2].kind, "other");
  EXPECT_EQ(all[2].handled_by, "none");
  EXPECT_EQ(all[2].location, "001/001 usb1");

  options.sysfs_root.clear();
  EXPECT_EQ(describe_usb_devices(devices, options)[0].detail.find("can0"), std::string::npos) << "sysfs skipped";
}

TEST(UsbDevices, TableIsAlignedText) {
  const FakeSysfs sysfs;
  UsbRowOptions options;
  options.sysfs_root = sysfs.root();
  const std::vector<UsbDeviceRow> rows =
      describe_usb_devices({device(1, 7, {2}, 0x0c72, 0x000c), device(1, 8, {3, 1}, 0x045e, 0x02ae)}, options);
  const std::string table = format_usb_device_table(rows, {"a note"});
  // Header, two rows, the note.
  std::vector<std::string> lines;
  for (std::size_t start = 0, end; (end = table.find('\n', start)) != std::string::npos; start = end + 1) {
    lines.push_back(table.substr(start, end - start));
  }
  ASSERT_EQ(lines.size(), 4u) << table;
  EXPECT_EQ(lines[0].rfind("NAME", 0), 0u);
  const std::size_t id_column = lines[0].find("VID:PID");
  ASSERT_NE(id_column, std::string::npos);
  EXPECT_EQ(lines[1].substr(id_column, 9), "0c72:000c") << table;
  EXPECT_EQ(lines[2].substr(id_column, 9), "045e:02ae") << table;
  EXPECT_EQ(lines[3], "note: a note");
  EXPECT_EQ(format_usb_device_table({}, {}), "no known USB devices found\n");
}

TEST(UsbDevices, ListingNeverFails) {
  std::vector<std::string> notes;
  UsbRowOptions options;
  options.include_unknown = true;
  const std::vector<UsbDeviceRow> rows = list_usb_devices(options, notes);
  // Whatever this machine has (a container: nothing, and a note saying so).
  if (rows.empty()) {
    EXPECT_FALSE(notes.empty());
  }
  for (const UsbDeviceRow& row : rows) EXPECT_EQ(row.id.size(), 9u);
  EXPECT_FALSE(format_usb_device_table(rows, notes).empty());
}

}  // namespace
