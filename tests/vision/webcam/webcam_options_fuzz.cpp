// libFuzzer target over the webcam front end's option parsers and grid seeding: the text a user
// gives to --roi, --grid, --support, --driven and --flow, a mask, and the role choice on top.
// Any input must end in a result or an InputError, never a crash, a hang or another exception.
//
// Input layout: five '\n'-separated fields (roi, grid, support, driven, flow), then the rest of
// the bytes: a spacing byte, then a 40 x 30 mask (one byte per pixel) when enough bytes remain,
// then per-particle motions.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_flow.hpp"
#include "pliant/vision/webcam_grid.hpp"
#include "pliant/vision/webcam_roles.hpp"

namespace webcam = pliant::vision::webcam;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (fields.size() < 5) {
    const std::size_t end = text.find('\n', start);
    if (end == std::string::npos) break;
    fields.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  const std::string rest = start <= text.size() ? text.substr(start) : std::string();
  while (fields.size() < 5) fields.emplace_back();

  const cv::Size frame(40, 30);
  webcam::Region region;
  webcam::GridSpec grid;
  webcam::SupportSpec support;
  webcam::DrivenSpec driven;
  try {
    region = webcam::parse_roi(fields[0]);
  } catch (const webcam::InputError&) {
    region.roi = cv::Rect(0, 0, 40, 30);
    region.label = "fuzz";
  }
  try {
    grid = webcam::parse_grid(fields[1]);
  } catch (const webcam::InputError&) {
  }
  try {
    support = webcam::parse_support(fields[2]);
  } catch (const webcam::InputError&) {
  }
  try {
    driven = webcam::parse_driven(fields[3]);
  } catch (const webcam::InputError&) {
  }
  try {
    (void)webcam::parse_flow_method(fields[4]);
  } catch (const webcam::InputError&) {
  }

  std::size_t at = 0;
  if (at < rest.size()) grid.spacing_px = static_cast<std::uint8_t>(rest[at++]) / 4.0;
  const std::size_t mask_bytes = static_cast<std::size_t>(frame.area());
  if (rest.size() - at >= mask_bytes) {
    region.mask = cv::Mat(frame, CV_8UC1);
    for (std::size_t i = 0; i < mask_bytes; ++i) region.mask.data[i] = static_cast<std::uint8_t>(rest[at + i]) & 1u;
    at += mask_bytes;
  }
  try {
    const webcam::ParticleGrid particles = webcam::seed_particles(region, grid, frame);
    std::vector<double> motion(static_cast<std::size_t>(particles.size()), 0.0);
    for (std::size_t i = 0; i < motion.size() && at < rest.size(); ++i) {
      motion[i] = static_cast<std::uint8_t>(rest[at++]) / 16.0;
    }
    (void)webcam::choose_roles(particles, motion, support, driven);
  } catch (const webcam::InputError&) {
  }
  return 0;
}
