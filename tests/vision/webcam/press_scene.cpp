#include "press_scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>

#include "pliant/core/msm.hpp"

namespace pliant::vision::webcam::test {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kWaves = 24;
constexpr int kPad = 2;

// A small deterministic generator (the same numbers on every platform and library).
class Lcg {
 public:
  explicit Lcg(std::uint64_t seed) : state_(seed * 2862933555777941757ULL + 3037000493ULL) {}
  double uniform() {
    state_ = state_ * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state_ >> 11) * (1.0 / 9007199254740992.0);
  }
  double normal() {
    const double u1 = std::max(uniform(), 1e-300), u2 = uniform();
    return std::sqrt(-2 * std::log(u1)) * std::cos(2 * kPi * u2);
  }

 private:
  std::uint64_t state_;
};

void require(Status status, const char* what) {
  if (status != Status::ok) throw std::runtime_error(std::string(what) + ": " + status_name(status));
}

// Catmull-Rom weights at t in [0, 1] for the nodes -1, 0, 1, 2.
void catmull_rom(double t, double w[4]) {
  const double t2 = t * t, t3 = t2 * t;
  w[0] = 0.5 * (-t3 + 2 * t2 - t);
  w[1] = 0.5 * (3 * t3 - 5 * t2 + 2);
  w[2] = 0.5 * (-3 * t3 + 4 * t2 + t);
  w[3] = 0.5 * (t3 - t2);
}

// Linear interpolation between the nodes 0 and 1 in the same four-node form.
void linear_weights(double t, double w[4]) {
  w[0] = 0;
  w[1] = 1 - t;
  w[2] = t;
  w[3] = 0;
}

}  // namespace

PressScene::PressScene(const PressSceneConfig& config) : config_(config) {
  const int rows = config.rows, cols = config.cols, n = rows * cols;
  std::vector<double> rest(static_cast<std::size_t>(2 * n));
  std::vector<std::uint8_t> fixed(static_cast<std::size_t>(n), 0);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const std::size_t i = static_cast<std::size_t>(r * cols + c);
      rest[2 * i] = config.x0 + c * config.spacing_px;
      rest[2 * i + 1] = config.y0 + r * config.spacing_px;
      fixed[i] = r == rows - 1 ? 1 : 0;
    }
  }
  const int tool = config.tool_col;
  MsmModelConfig<2, double> mc;
  mc.particle_count = n;
  mc.rest_positions = rest.data();
  mc.fixed = fixed.data();
  mc.drivable_ids = &tool;
  mc.drivable_count = 1;
  const std::size_t model_bytes = msm_model_workspace_size(mc);
  std::vector<unsigned char> model_block(model_bytes);
  Arena model_arena(model_block.data(), model_bytes);
  MsmModel<2, double> model;
  require(msm_model_init(model_arena, mc, model), "scene model");
  const std::size_t state_bytes = msm_state_workspace_size(model);
  std::vector<unsigned char> state_block(state_bytes);
  Arena state_arena(state_block.data(), state_bytes);
  MsmState<2, double> state;
  require(msm_state_init(state_arena, model, state), "scene state");
  MsmParams<2, double> params;
  params.msm_beta = config.msm_beta;

  const int frames = config.still_frames + config.press_frames + config.hold_frames;
  const auto snapshot = [&] {
    std::vector<cv::Point2d> positions(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) positions[static_cast<std::size_t>(i)] = {state.position[i](0), state.position[i](1)};
    truth_.push_back(positions);
  };
  snapshot();
  for (int k = 1; k < frames; ++k) {
    const double progress =
        std::clamp(static_cast<double>(k - config.still_frames + 1) / config.press_frames, 0.0, 1.0);
    Eigen::Vector2d target = model.rest[tool];
    target(1) += config.depth_px * progress;
    MsmStepInput<2, double> in;
    in.dt = 1.0 / config.rate_hz;
    in.driven = {&tool, &target, 1};
    require(msm_step(model, params, in, state), "scene step");
    snapshot();
  }

  // Displacements on the lattice padded by two nodes per side, extended linearly.
  const int prow = rows + 2 * kPad, pcol = cols + 2 * kPad;
  for (const std::vector<cv::Point2d>& positions : truth_) {
    std::vector<cv::Point2d> pad(static_cast<std::size_t>(prow * pcol));
    const auto at = [&](int r, int c) -> cv::Point2d& {
      return pad[static_cast<std::size_t>((r + kPad) * pcol + c + kPad)];
    };
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        const std::size_t i = static_cast<std::size_t>(r * cols + c);
        at(r, c) = positions[i] - cv::Point2d(rest[2 * i], rest[2 * i + 1]);
      }
      for (int c = -1; c >= -kPad; --c) at(r, c) = 2 * at(r, c + 1) - at(r, c + 2);
      for (int c = cols; c < cols + kPad; ++c) at(r, c) = 2 * at(r, c - 1) - at(r, c - 2);
    }
    for (int c = -kPad; c < cols + kPad; ++c) {
      for (int r = -1; r >= -kPad; --r) at(r, c) = 2 * at(r + 1, c) - at(r + 2, c);
      for (int r = rows; r < rows + kPad; ++r) at(r, c) = 2 * at(r - 1, c) - at(r - 2, c);
    }
    padded_.push_back(std::move(pad));
  }

  Lcg rng(config.seed);
  for (auto& layer : waves_) {
    for (int k = 0; k < kWaves; ++k) {
      const double wavelength = 6.0 * std::pow(5.0, rng.uniform());  // 6 .. 30 px
      const double angle = 2 * kPi * rng.uniform();
      layer.push_back(
          {2 * kPi * std::cos(angle) / wavelength, 2 * kPi * std::sin(angle) / wavelength, 2 * kPi * rng.uniform()});
    }
  }
}

cv::Point2d PressScene::displacement(int frame, const cv::Point2d& u) const {
  const int rows = config_.rows, cols = config_.cols, pcol = cols + 2 * kPad;
  const std::vector<cv::Point2d>& pad = padded_[static_cast<std::size_t>(frame)];
  const double tx = std::clamp((u.x - config_.x0) / config_.spacing_px, -1.0, static_cast<double>(cols));
  const double ty = std::clamp((u.y - config_.y0) / config_.spacing_px, -1.0, static_cast<double>(rows));
  const int ix = std::clamp(static_cast<int>(std::floor(tx)), -1, cols - 1);
  const int iy = std::clamp(static_cast<int>(std::floor(ty)), -1, rows - 1);
  double wx[4], wy[4];
  if (config_.bilinear) {
    linear_weights(tx - ix, wx);
    linear_weights(ty - iy, wy);
  } else {
    catmull_rom(tx - ix, wx);
    catmull_rom(ty - iy, wy);
  }
  cv::Point2d d(0, 0);
  for (int j = 0; j < 4; ++j) {
    cv::Point2d line(0, 0);
    const std::size_t base = static_cast<std::size_t>((iy - 1 + j + kPad) * pcol + ix - 1 + kPad);
    for (int i = 0; i < 4; ++i) line += wx[i] * pad[base + static_cast<std::size_t>(i)];
    d += wy[j] * line;
  }
  return d;
}

double PressScene::texture(const cv::Point2d& u, int layer) const {
  double sum = 0;
  for (const Wave& w : waves_[layer]) sum += std::sin(w.kx * u.x + w.ky * u.y + w.phase);
  return 128.0 + 60.0 * sum / std::sqrt(0.5 * kWaves);
}

cv::Rect2d PressScene::occluder(int frame) const {
  if (config_.occluder_width <= 0 || frame < config_.occluder_from) return {};
  const double x = config_.occluder_x0 + (frame - config_.occluder_from) * config_.occluder_speed_px;
  return {x, config_.occluder_y, static_cast<double>(config_.occluder_width),
          static_cast<double>(config_.occluder_height)};
}

bool PressScene::hidden(int frame, int id, double margin_px) const {
  const cv::Rect2d box = occluder(frame);
  if (box.width <= 0) return false;
  const cv::Point2d p = truth(frame, id);
  return p.x >= box.x - margin_px && p.x <= box.x + box.width + margin_px && p.y >= box.y - margin_px &&
         p.y <= box.y + box.height + margin_px;
}

cv::Mat PressScene::render(int frame) const {
  cv::Mat image(config_.height, config_.width, CV_8UC1);
  Lcg noise(config_.seed * 1000003u + static_cast<unsigned>(frame));
  const cv::Rect2d box = occluder(frame);
  for (int y = 0; y < config_.height; ++y) {
    cv::Point2d u(0, y);  // warm start carried along the row
    bool warm = false;
    for (int x = 0; x < config_.width; ++x) {
      const cv::Point2d target(x, y);
      double value = 0;
      if (box.width > 0 && box.contains(target)) {
        value = texture(target - box.tl(), 1);
      } else {
        // Solve u + D(u) = target by fixed-point iteration (|grad D| < 1 here).
        if (!warm) u = target - displacement(frame, target);
        for (int it = 0; it < 100; ++it) {
          const cv::Point2d next = target - displacement(frame, u);
          const double step = std::hypot(next.x - u.x, next.y - u.y);
          u = next;
          if (step < 1e-6) break;
        }
        warm = true;
        value = texture(u, 0);
        u += cv::Point2d(1, 0);
      }
      value += config_.noise_grey * noise.normal();
      image.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(value);
    }
  }
  return image;
}

std::vector<cv::Mat> PressScene::render_all() const {
  std::vector<cv::Mat> frames;
  for (int k = 0; k < frame_count(); ++k) frames.push_back(render(k));
  return frames;
}

std::string PressScene::roi() const {
  const double half = 0.5 * config_.spacing_px;
  const auto x = static_cast<long>(std::lround(config_.x0 - half + 0.5));
  const auto y = static_cast<long>(std::lround(config_.y0 - half + 0.5));
  const auto w = static_cast<long>(std::lround(config_.cols * config_.spacing_px));
  const auto h = static_cast<long>(std::lround(config_.rows * config_.spacing_px));
  return std::to_string(x) + "," + std::to_string(y) + "," + std::to_string(w) + "," + std::to_string(h);
}

std::string PressScene::grid() const { return std::to_string(config_.rows) + "x" + std::to_string(config_.cols); }

std::vector<int> PressScene::base() const {
  std::vector<int> ids;
  for (int c = 0; c < config_.cols; ++c) ids.push_back((config_.rows - 1) * config_.cols + c);
  return ids;
}

}  // namespace pliant::vision::webcam::test
