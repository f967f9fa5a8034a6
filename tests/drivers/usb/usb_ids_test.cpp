// drivers/usb usb_ids: lookups of the VID:PID table (docs/drivers/usb.md).
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "pliant/drivers/usb/usb_ids.hpp"

namespace {

using namespace pliant::drivers::usb;

TEST(UsbIds, FindsTheDepthCameras) {
  const UsbIdEntry* kinect = lookup_usb_id(0x045e, 0x02ae);
  ASSERT_NE(kinect, nullptr);
  EXPECT_EQ(kinect->kind, UsbDeviceKind::depth_camera);
  EXPECT_STREQ(kinect->handled_by, "openni2");
  EXPECT_NE(std::string(kinect->note).find("libfreenect"), std::string::npos);
  const UsbIdEntry* motor = lookup_usb_id(0x045e, 0x02b0);
  ASSERT_NE(motor, nullptr);
  EXPECT_EQ(motor->kind, UsbDeviceKind::camera_part);
  EXPECT_STREQ(motor->handled_by, "none");
  const UsbIdEntry* xtion = lookup_usb_id(0x1d27, 0x0601);
  ASSERT_NE(xtion, nullptr);
  EXPECT_NE(std::string(xtion->name).find("Xtion PRO LIVE"), std::string::npos);
  EXPECT_STREQ(xtion->handled_by, "openni2");
  EXPECT_STREQ(lookup_usb_id(0x2bc5, 0x0401)->name, "Orbbec Astra");
  EXPECT_STREQ(lookup_usb_id(0x8086, 0x0b07)->name, "Intel RealSense D435");
  EXPECT_STREQ(lookup_usb_id(0x8086, 0x0b07)->handled_by, "none");
  EXPECT_STREQ(lookup_usb_id(0x045e, 0x02d9)->handled_by, "none") << "Kinect v2";
  EXPECT_STREQ(lookup_usb_id(0x1d27, 0xf9db)->name, "PrimeSense PSLink sensor");
}

TEST(UsbIds, FindsTheCanAdapters) {
  const std::pair<std::uint16_t, std::uint16_t> adapters[] = {
      {0x0c72, 0x000c}, {0x0c72, 0x000d}, {0x0c72, 0x0011}, {0x0c72, 0x0012}, {0x0c72, 0x0013}, {0x0c72, 0x0014},
      {0x1d50, 0x606f}, {0x1209, 0x2323}, {0x1cd2, 0x606f}, {0x16d0, 0x10b8}, {0x16d0, 0x0f30}, {0x0bfd, 0x0120}};
  for (const auto& [vid, pid] : adapters) {
    const UsbIdEntry* entry = lookup_usb_id(vid, pid);
    ASSERT_NE(entry, nullptr) << std::hex << vid << ":" << pid;
    EXPECT_EQ(entry->kind, UsbDeviceKind::can_adapter);
    EXPECT_STREQ(entry->handled_by, "socketcan");
  }
  EXPECT_STREQ(lookup_usb_id(0x0c72, 0x000c)->name, "PEAK PCAN-USB");
  EXPECT_NE(std::string(lookup_usb_id(0x1d50, 0x606f)->note).find("gs_usb"), std::string::npos);
}

TEST(UsbIds, RangesAndVendorsMatchOnlyWhereTheyShould) {
  EXPECT_EQ(lookup_usb_id(0x2bc5, 0x0510)->kind, UsbDeviceKind::camera_part) << "Orbbec UVC colour range";
  EXPECT_STREQ(lookup_usb_id(0x2bc5, 0x0510)->handled_by, "opencv");
  EXPECT_STREQ(lookup_usb_id(0x2bc5, 0x0521)->name, "Orbbec device (unknown model)");
  EXPECT_STREQ(lookup_usb_id(0x1d27, 0x1234)->name, "PrimeSense device (unknown model)");
  EXPECT_STREQ(lookup_usb_id(0x0bfd, 0x0999)->name, "Kvaser CAN interface (unknown model)");
  // Shared vendor ids: only the listed products.
  EXPECT_EQ(lookup_usb_id(0x8086, 0x0001), nullptr) << "Intel";
  EXPECT_EQ(lookup_usb_id(0x1d50, 0x6070), nullptr) << "OpenMoko";
  EXPECT_EQ(lookup_usb_id(0x1209, 0x0001), nullptr) << "pid.codes";
  EXPECT_EQ(lookup_usb_id(0x16d0, 0x117e), nullptr) << "MCS";
  EXPECT_EQ(lookup_usb_id(0x045e, 0x0001), nullptr) << "Microsoft";
  EXPECT_EQ(lookup_usb_id(0x0000, 0x0000), nullptr);
  EXPECT_EQ(lookup_usb_id(0xffff, 0xffff), nullptr);
}

TEST(UsbIds, TableIsWellFormed) {
  std::size_t count = 0;
  const UsbIdEntry* table = usb_id_table(count);
  ASSERT_GT(count, 40u);
  std::set<std::string> handlers;
  for (std::size_t i = 0; i < count; ++i) {
    const UsbIdEntry& e = table[i];
    EXPECT_LE(e.product_first, e.product_last) << e.name;
    EXPECT_NE(e.name, nullptr);
    EXPECT_GT(std::string(e.name).size(), 3u);
    handlers.insert(e.handled_by);
    // Every entry is reachable: no earlier entry hides its first product.
    EXPECT_EQ(lookup_usb_id(e.vendor_id, e.product_first), &e) << e.name;
  }
  EXPECT_EQ(handlers, (std::set<std::string>{"openni2", "socketcan", "opencv", "none"}));
  EXPECT_STREQ(usb_device_kind_name(UsbDeviceKind::can_adapter), "can_adapter");
}

}  // namespace
