// Helpers shared by the webcam tests: temporary directories, synthetic textures and files.
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "../../support/temp_dir.hpp"

namespace pliant::vision::webcam::test {

namespace fs = std::filesystem;

class TempDir : public test_support::TempDir {
 public:
  TempDir() : test_support::TempDir("pliant_webcam_") {}
};

/// A smooth random texture (seeded), CV_8UC1, blurred noise with structure at a few pixels.
inline cv::Mat random_texture(int width, int height, unsigned seed) {
  cv::Mat noise(height, width, CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
  cv::Mat smooth;
  cv::GaussianBlur(noise, smooth, cv::Size(0, 0), 1.5);
  cv::Mat out;
  cv::normalize(smooth, smooth, 0, 1, cv::NORM_MINMAX);
  smooth.convertTo(out, CV_8U, 230, 10);
  return out;
}

/// `texture` shifted by (dx, dy) pixels (content moves right/down), bilinear, edges replicated.
inline cv::Mat shifted(const cv::Mat& texture, double dx, double dy) {
  cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::Mat out;
  cv::warpAffine(texture, out, m, texture.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

inline void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

inline void write_png(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace pliant::vision::webcam::test
