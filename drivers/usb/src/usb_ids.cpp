#include "pliant/drivers/usb/usb_ids.hpp"

namespace pliant::drivers::usb {
namespace {

constexpr UsbDeviceKind kDepth = UsbDeviceKind::depth_camera;
constexpr UsbDeviceKind kPart = UsbDeviceKind::camera_part;
constexpr UsbDeviceKind kCan = UsbDeviceKind::can_adapter;

constexpr const char* kFreenectNote =
    "OpenNI2 needs libfreenect's OpenNI2 driver (libFreenectDriver), which Debian does not ship";
constexpr const char* kOrbbecNote = "OpenNI2 needs Orbbec's OpenNI2 driver (liborbbec), which Debian does not ship";
constexpr const char* kPs1080Note = "Debian's libPS1080 OpenNI2 driver";
constexpr const char* kPsLinkNote = "Debian's libPSLink OpenNI2 driver";
constexpr const char* kRealSenseNote = "needs librealsense2; pliant has no RealSense driver";
constexpr const char* kPeakNote = "kernel driver peak_usb gives a canN interface";
constexpr const char* kGsUsbNote = "kernel driver gs_usb gives a canN interface";
constexpr const char* kGsUsbNewNote = "kernel driver gs_usb in newer kernels (not checked for Debian 12's 6.1)";
constexpr const char* kKvaserNote = "kernel driver kvaser_usb gives a canN interface";

// Specific products first, then ranges, then whole vendors (see the header).
constexpr UsbIdEntry kTable[] = {
    // Microsoft Kinect v1 (libfreenect src/freenect_internal.h).
    {0x045e, 0x02ae, 0x02ae, kDepth, "Microsoft Kinect v1 (Xbox 360) camera", "openni2", kFreenectNote},
    {0x045e, 0x02b0, 0x02b0, kPart, "Microsoft Kinect v1 (Xbox 360) motor", "none", "tilt motor and accelerometer"},
    {0x045e, 0x02ad, 0x02ad, kPart, "Microsoft Kinect v1 (Xbox 360) audio", "none", "microphone array"},
    {0x045e, 0x02bf, 0x02bf, kDepth, "Microsoft Kinect for Windows v1 camera", "openni2", kFreenectNote},
    {0x045e, 0x02be, 0x02be, kPart, "Microsoft Kinect for Windows v1 audio", "none", "microphone array"},
    {0x045e, 0x02c3, 0x02c3, kPart, "Microsoft Kinect for Windows v1 audio (SDK firmware)", "none", "microphone array"},
    {0x045e, 0x02bb, 0x02bb, kPart, "Microsoft Kinect for Windows v1 audio (beta firmware)", "none",
     "microphone array"},
    {0x045e, 0x02d9, 0x02d9, kDepth, "Microsoft Kinect v2", "none",
     "needs libfreenect2; OpenNI2 has no Kinect v2 driver"},
    // PrimeSense PS1080 family (OpenNI2 Source/Drivers/PS1080/Sensor/XnDeviceEnumeration.cpp).
    {0x1d27, 0x0500, 0x0500, kDepth, "PrimeSense PS1080 sensor", "openni2", kPs1080Note},
    {0x1d27, 0x0600, 0x0600, kDepth, "ASUS Xtion PRO (PS1080)", "openni2", kPs1080Note},
    {0x1d27, 0x0601, 0x0601, kDepth, "ASUS Xtion PRO LIVE (PS1080)", "openni2", kPs1080Note},
    {0x1d27, 0x0609, 0x0609, kDepth, "PrimeSense PS1080 sensor", "openni2", kPs1080Note},
    // PrimeSense PSLink devices (OpenNI2 Source/Drivers/PSLink/LinkDeviceEnumeration.cpp).
    {0x1d27, 0x1250, 0x1250, kDepth, "PrimeSense PSLink sensor", "openni2", kPsLinkNote},
    {0x1d27, 0x1260, 0x1260, kDepth, "PrimeSense PSLink sensor", "openni2", kPsLinkNote},
    {0x1d27, 0x1270, 0x1270, kDepth, "PrimeSense PSLink sensor", "openni2", kPsLinkNote},
    {0x1d27, 0x1280, 0x1280, kDepth, "PrimeSense PSLink sensor", "openni2", kPsLinkNote},
    {0x1d27, 0x1290, 0x1290, kDepth, "PrimeSense PSLink sensor", "openni2", kPsLinkNote},
    {0x1d27, 0xf9db, 0xf9db, kDepth, "PrimeSense PSLink sensor", "openni2", kPsLinkNote},
    // Orbbec (orbbec/ros_astra_camera 56-orbbec-usb.rules).
    {0x2bc5, 0x0401, 0x0401, kDepth, "Orbbec Astra", "openni2", kOrbbecNote},
    {0x2bc5, 0x0402, 0x0402, kDepth, "Orbbec Astra S", "openni2", kOrbbecNote},
    {0x2bc5, 0x0403, 0x0403, kDepth, "Orbbec Astra Pro", "openni2", kOrbbecNote},
    {0x2bc5, 0x0404, 0x0404, kDepth, "Orbbec Astra Mini", "openni2", kOrbbecNote},
    {0x2bc5, 0x0407, 0x0407, kDepth, "Orbbec Astra Mini S", "openni2", kOrbbecNote},
    {0x2bc5, 0x060d, 0x060d, kDepth, "Orbbec Astra Pro Plus", "openni2", kOrbbecNote},
    {0x2bc5, 0x065c, 0x065c, kDepth, "Orbbec Gemini E", "openni2", kOrbbecNote},
    // Intel RealSense D400 (librealsense src/ds/d400/d400-private.h).
    {0x8086, 0x0ad3, 0x0ad3, kDepth, "Intel RealSense D415", "none", kRealSenseNote},
    {0x8086, 0x0b07, 0x0b07, kDepth, "Intel RealSense D435", "none", kRealSenseNote},
    {0x8086, 0x0b3a, 0x0b3a, kDepth, "Intel RealSense D435i", "none", kRealSenseNote},
    {0x8086, 0x0b5c, 0x0b5c, kDepth, "Intel RealSense D455", "none", kRealSenseNote},
    {0x8086, 0x0b5b, 0x0b5b, kDepth, "Intel RealSense D405", "none", kRealSenseNote},
    // PEAK-System (Linux drivers/net/can/usb/peak_usb/pcan_usb_core.h).
    {0x0c72, 0x000c, 0x000c, kCan, "PEAK PCAN-USB", "socketcan", kPeakNote},
    {0x0c72, 0x000d, 0x000d, kCan, "PEAK PCAN-USB Pro", "socketcan", kPeakNote},
    {0x0c72, 0x0011, 0x0011, kCan, "PEAK PCAN-USB Pro FD", "socketcan", kPeakNote},
    {0x0c72, 0x0012, 0x0012, kCan, "PEAK PCAN-USB FD", "socketcan", kPeakNote},
    {0x0c72, 0x0013, 0x0013, kCan, "PEAK PCAN-Chip USB", "socketcan", kPeakNote},
    {0x0c72, 0x0014, 0x0014, kCan, "PEAK PCAN-USB X6", "socketcan", kPeakNote},
    // gs_usb devices (Linux drivers/net/can/usb/gs_usb.c).
    {0x1d50, 0x606f, 0x606f, kCan, "Geschwister Schneider USB/CAN (candleLight, CANable gs_usb firmware)", "socketcan",
     kGsUsbNote},
    {0x1209, 0x2323, 0x2323, kCan, "candleLight USB-CAN", "socketcan", kGsUsbNote},
    {0x1cd2, 0x606f, 0x606f, kCan, "CES CANext FD", "socketcan", kGsUsbNewNote},
    {0x16d0, 0x10b8, 0x10b8, kCan, "ABE CANdebugger FD", "socketcan", kGsUsbNewNote},
    {0x16d0, 0x0f30, 0x0f30, kCan, "Xylanta SAINT3", "socketcan", kGsUsbNewNote},
    // Kvaser (Linux drivers/net/can/usb/kvaser_usb/kvaser_usb_core.c).
    {0x0bfd, 0x0004, 0x0004, kCan, "Kvaser USBcan II", "socketcan", kKvaserNote},
    {0x0bfd, 0x000b, 0x000b, kCan, "Kvaser Leaf Light", "socketcan", kKvaserNote},
    {0x0bfd, 0x0107, 0x0107, kCan, "Kvaser Leaf Pro HS v2", "socketcan", kKvaserNote},
    {0x0bfd, 0x0120, 0x0120, kCan, "Kvaser Leaf Light v2", "socketcan", kKvaserNote},
    {0x0bfd, 0x0123, 0x0123, kCan, "Kvaser USBcan Light 2xHS", "socketcan", kKvaserNote},
    // Ranges.
    {0x2bc5, 0x0501, 0x0520, kPart, "Orbbec UVC colour camera", "opencv",
     "the colour side of an Astra Pro-type camera: a UVC webcam (/dev/videoN)"},
    // Whole vendors.
    {0x1d27, 0x0000, 0xffff, kDepth, "PrimeSense device (unknown model)", "openni2",
     "may be served by libPS1080 or libPSLink"},
    {0x2bc5, 0x0000, 0xffff, kDepth, "Orbbec device (unknown model)", "openni2", kOrbbecNote},
    {0x0bfd, 0x0000, 0xffff, kCan, "Kvaser CAN interface (unknown model)", "socketcan", kKvaserNote},
};

}  // namespace

const char* usb_device_kind_name(UsbDeviceKind kind) noexcept {
  switch (kind) {
    case UsbDeviceKind::depth_camera: return "depth_camera";
    case UsbDeviceKind::camera_part: return "camera_part";
    case UsbDeviceKind::can_adapter: return "can_adapter";
  }
  return "unknown";
}

const UsbIdEntry* usb_id_table(std::size_t& count) noexcept {
  count = sizeof kTable / sizeof kTable[0];
  return kTable;
}

const UsbIdEntry* lookup_usb_id(std::uint16_t vendor_id, std::uint16_t product_id) noexcept {
  for (const UsbIdEntry& entry : kTable) {
    if (entry.vendor_id == vendor_id && product_id >= entry.product_first && product_id <= entry.product_last)
      return &entry;
  }
  return nullptr;
}

}  // namespace pliant::drivers::usb
