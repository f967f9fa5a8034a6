// Uses one piece of each installed component that the consumer was configured with
// (PLIANT_CONSUMER_<COMPONENT> = 1), so that its headers, its library and the dependencies its
// export set names are all found and linked from the install prefix.
// Usage: components [RECORDING_DIR]   (RECORDING_DIR: a recording for the host component)
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#if PLIANT_CONSUMER_HOST
#include <pliant/host/estimate.hpp>
#include <pliant/host/recording.hpp>
#endif
#if PLIANT_CONSUMER_VISION
#include <pliant/vision/depth_cloud.hpp>
#endif
#if PLIANT_CONSUMER_WEBCAM
#include <pliant/vision/webcam_error.hpp>
#include <pliant/vision/webcam_frames.hpp>
#endif
#if PLIANT_CONSUMER_SOCKETCAN
#include <pliant/drivers/socketcan/ati_netcanoem_protocol.hpp>
#endif
#if PLIANT_CONSUMER_MODBUS
#include <pliant/drivers/modbus/modbus_crc.hpp>
#endif
#if PLIANT_CONSUMER_OPENCV
#include <pliant/drivers/opencv/file_readers.hpp>
#include <pliant/drivers/opencv/image_files.hpp>
#include <pliant/drivers/opencv/opencv_camera.hpp>
#endif
#if PLIANT_CONSUMER_LIBCAMERA
#include <pliant/drivers/libcamera/libcamera_camera.hpp>
#endif
#if PLIANT_CONSUMER_OPENNI2
#include <pliant/drivers/openni2/depth_points.hpp>
#endif
#if PLIANT_CONSUMER_USB
#include <pliant/drivers/usb/usb_ids.hpp>
#endif

namespace {

int failures = 0;

void expect(bool ok, const char* what) {
  std::printf("components: %s %s\n", what, ok ? "ok" : "FAILED");
  if (!ok) ++failures;
}

}  // namespace

int main(int argc, char** argv) {
  (void)argc;
  (void)argv;
#if PLIANT_CONSUMER_HOST
  if (argc < 2) {
    std::printf("components: host needs a recording directory\n");
    return 2;
  }
  const pliant::host::Recording recording = pliant::host::read_recording(argv[1]);
  pliant::host::EstimateOptions options;
  const pliant::host::EstimateReport report = pliant::host::estimate_recording(recording, options);
  expect(report.result.msm_beta >= 0 && report.result.msm_beta <= 1, "host: msm_beta of the recording in [0, 1]");
#endif
#if PLIANT_CONSUMER_VISION
  std::vector<std::uint16_t> depth(4 * 3, 1000);
  pliant::vision::DepthImageView image;
  image.data = depth.data();
  image.width = 4;
  image.height = 3;
  pliant::vision::PinholeIntrinsics intrinsics{500, 500, 2, 1.5, 4, 3};
  pliant::vision::DepthCloud cloud;
  expect(pliant::vision::depth_to_cloud(image, intrinsics, {}, cloud) == 12, "vision: 12 points from a 4x3 image");
#endif
#if PLIANT_CONSUMER_WEBCAM
  // The webcam front end lists sequences through the opencv driver (a link the export carries).
  bool refused = false;
  try {
    pliant::vision::webcam::expand_image_pattern("/nonexistent/pliant/*.png");
  } catch (const pliant::vision::webcam::InputError& e) {
    refused = std::string(e.what()).find("no file matches") != std::string::npos;
  }
  expect(refused, "vision: webcam glob that matches nothing refused");
#endif
#if PLIANT_CONSUMER_SOCKETCAN
  namespace ati = pliant::drivers::socketcan::ati;
  expect(ati::valid_base_id(0x20), "socketcan: ATI base ID 0x20 valid");
#endif
#if PLIANT_CONSUMER_MODBUS
  const std::uint8_t frame[] = {0x09, 0x03, 0x07, 0xd0, 0x00, 0x03};  // read 3 registers at 2000
  expect(pliant::drivers::modbus::modbus_crc16(frame, sizeof frame) != 0, "modbus: CRC-16 computed");
#endif
#if PLIANT_CONSUMER_OPENCV
  expect(std::string(pliant::drivers::opencv_source_name(pliant::drivers::OpenCvSource::video_file)).size() > 0,
         "opencv: source names");
  {
    namespace files = pliant::drivers::opencv_files;
    files::SequencePattern pattern;
    std::string words;
    expect(
        files::parse_sequence_pattern("f_%03d.png", pattern, words) && files::sequence_name(pattern, 7) == "f_007.png",
        "opencv: image sequence naming");
    expect(files::read_image("/nonexistent/pliant.png", files::ImageDecoding::as_stored).empty(),
           "opencv: a missing image reads empty");
  }
#endif
#if PLIANT_CONSUMER_LIBCAMERA
  std::string error;
  (void)pliant::drivers::list_libcamera_cameras(&error);
  expect(true, "libcamera: camera list asked (may be empty)");
#endif
#if PLIANT_CONSUMER_OPENNI2
  expect(pliant::drivers::openni2::fov_is_valid(1.0, 0.8), "openni2: field of view check");
#endif
#if PLIANT_CONSUMER_USB
  std::size_t count = 0;
  expect(pliant::drivers::usb::usb_id_table(count) != nullptr && count > 0, "usb: VID:PID table");
#endif
  return failures == 0 ? 0 : 1;
}
