// A rendered ground truth for the webcam tracker: a textured object pressed by a tool, deformed
// by a known MSM simulation, optionally crossed by a moving occluder.
//
// The object's particles sit on a rows x cols lattice (spacing_px apart, first at (x0, y0),
// pixel convention of webcam_grid.hpp). The bottom row rests on the base (fixed), the top-row
// particle of column tool_col is driven down by depth_px over press_frames and held; the other
// particles follow core msm_step with msm_beta (radius clusters, as `pliant estimate` builds
// them), one step per frame. Frame k shows the texture carried by the displacement field of
// frame k: the particles' displacements interpolated with Catmull-Rom splines over the lattice
// (smooth, exact at the particles), extended linearly one spacing beyond it and held constant
// further out; each pixel x shows the texture at the rest point u with u + D(u) = x. The
// texture is a fixed sum of sinusoids (wavelengths 6 - 30 px), so sub-pixel sampling is exact.
// Grey levels get Gaussian noise (sd noise_grey) and are rounded to 8 bits.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace pliant::vision::webcam::test {

struct PressSceneConfig {
  int width = 320;
  int height = 240;
  int rows = 4;
  int cols = 8;
  double spacing_px = 30;
  double x0 = 54.5;  ///< first particle (the --roi 40,60,240,120 cell centres with --grid 4x8)
  double y0 = 74.5;
  int tool_col = 4;
  double msm_beta = 0.6;
  double depth_px = 12;
  int still_frames = 3;
  int press_frames = 15;
  int hold_frames = 12;
  double rate_hz = 10;
  double noise_grey = 1.0;
  unsigned seed = 7;
  /// Occluder: a textured rectangle moving right at occluder_speed_px per frame, from
  /// occluder_x0 at frame occluder_from; off when occluder_width is 0.
  int occluder_width = 0;
  int occluder_height = 0;
  double occluder_x0 = 0;
  double occluder_y = 0;
  double occluder_speed_px = 0;
  int occluder_from = 0;
  /// Bilinear instead of Catmull-Rom interpolation of the displacements: a kink at every
  /// particle, as under a tool's point of contact, where the splines round the peak off.
  bool bilinear = false;
};

class PressScene {
 public:
  explicit PressScene(const PressSceneConfig& config);

  int frame_count() const { return static_cast<int>(truth_.size()); }
  int particle_count() const { return config_.rows * config_.cols; }
  const PressSceneConfig& config() const { return config_; }
  /// True particle position in frame k (px).
  cv::Point2d truth(int frame, int id) const {
    return truth_[static_cast<std::size_t>(frame)][static_cast<std::size_t>(id)];
  }
  /// Frame k, CV_8UC1.
  cv::Mat render(int frame) const;
  std::vector<cv::Mat> render_all() const;
  /// The occluder's rectangle in frame k (empty when off or not yet there).
  cv::Rect2d occluder(int frame) const;
  /// Whether particle `id` lies inside the occluder grown by `margin_px` in frame k.
  bool hidden(int frame, int id, double margin_px) const;

  /// --roi text whose --grid rows x cols cell centres are the lattice.
  std::string roi() const;
  std::string grid() const;
  int tool() const { return config_.tool_col; }
  std::vector<int> base() const;

 private:
  cv::Point2d displacement(int frame, const cv::Point2d& u) const;
  double texture(const cv::Point2d& u, int layer) const;

  PressSceneConfig config_;
  std::vector<std::vector<cv::Point2d>> truth_;
  std::vector<std::vector<cv::Point2d>> padded_;  // per frame: (rows + 4) x (cols + 4) displacements
  struct Wave {
    double kx, ky, phase;
  };
  std::vector<Wave> waves_[2];  // object, occluder
};

}  // namespace pliant::vision::webcam::test
