#include "pliant/host/diagnose/locate.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <stdexcept>

namespace pliant::host {
namespace {

constexpr double kNoiseFloor = 1e-9;    // noise-free input: this fraction of the scale
constexpr double kSignificance = 3.0;   // z for every "significant" test of the signatures
constexpr int kRestFrames = 5;          // frames averaged for a driver's final position
constexpr int kSupportRestFrames = 10;  // frames averaged for a support particle's rest
// Gate for pooled mean squares of few samples (skewed, chi-square-like): 4 standard deviations.
constexpr double kSmallSampleSignificance = 4.0;
constexpr double kTailFraction = 0.2;   // persistence: last 20% of the frames after unloading
constexpr int kVelocityHalfWindow = 2;  // velocities: slope over 5 frames
constexpr int kPeakHalfWindow = 2;      // persistence: peak of a 5-frame pooled mean square
// velocity_correlation: samples * R^2 must exceed 10 + 3 * dim (white noise: p < 1e-3).
constexpr double kChiSquareGate = 10.0;
constexpr double kChiSquarePerDof = 3.0;

std::size_t at(int frame, int id, int n, int dim) {
  return (static_cast<std::size_t>(frame) * static_cast<std::size_t>(n) + static_cast<std::size_t>(id)) *
         static_cast<std::size_t>(dim);
}

double squared(const double* a, const double* b, int dim) {
  double sum = 0;
  for (int d = 0; d < dim; ++d) sum += (a[d] - b[d]) * (a[d] - b[d]);
  return sum;
}

bool finite_point(const double* p, int dim) {
  for (int d = 0; d < dim; ++d) {
    if (!std::isfinite(p[d])) return false;
  }
  return true;
}

// Mean square `ms` of `samples` Euclidean residuals is clearly above the noise (see header).
bool clearly_above(double ms, double samples, int dim, double noise, double min_ratio, double z) {
  if (!(samples > 0) || !std::isfinite(ms)) return false;
  const double expected = dim * noise * noise;
  const double statistical = 1.0 + z * std::sqrt(2.0 / (samples * dim));
  return ms > expected * std::max(min_ratio * min_ratio, statistical);
}

double floored_noise(double noise_std, double scale) {
  if (noise_std > 0 && std::isfinite(noise_std)) return noise_std;
  return kNoiseFloor * scale;
}

void check_recording(const Recording& recording) {
  if (recording.dimension < 1 || recording.particle_count < 0)
    throw std::invalid_argument("bad dimension or particle count");
  if (recording.positions.size() != at(recording.frame_count(), 0, recording.particle_count, recording.dimension)) {
    throw std::invalid_argument("recording positions size does not match frames * particles * dimension");
  }
}

void check_field(const Recording& recording, const ResidualField& field) {
  check_recording(recording);
  const bool same_frames = field.frame_count == recording.frame_count() || recording.particle_count == 0;
  if (field.particle_count != recording.particle_count || field.dimension != recording.dimension || !same_frames ||
      field.residual.size() != at(field.frame_count, 0, field.particle_count, field.dimension)) {
    throw std::invalid_argument("residual field does not match the recording");
  }
}

std::vector<unsigned char> location_mask(const Location& location, int particle_count) {
  std::vector<unsigned char> mask(static_cast<std::size_t>(particle_count), 0);
  for (int id : location.particles) {
    if (id < 0 || id >= particle_count) throw std::invalid_argument("location particle id out of range");
    mask[static_cast<std::size_t>(id)] = 1;
  }
  return mask;
}

bool any_set(const std::vector<unsigned char>& mask) {
  return std::any_of(mask.begin(), mask.end(), [](unsigned char m) { return m != 0; });
}

const double* observed_point(const Recording& recording, int frame, int id) {
  return recording.positions.data() + at(frame, id, recording.particle_count, recording.dimension);
}

std::vector<int> driven_ids(const Recording& recording) {
  std::vector<int> ids;
  for (const DrivenWindow& window : recording.driven) {
    if (window.id >= 0 && window.id < recording.particle_count) ids.push_back(window.id);
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

bool driven_at(const Recording& recording, int id, double t_s) {
  return std::any_of(recording.driven.begin(), recording.driven.end(),
                     [&](const DrivenWindow& window) { return window.id == id && window.active_at(t_s); });
}

// Rest positions (particle-major, particle_count * dimension): the recording's when complete,
// else each particle's first observed position (NaN for a never-observed particle).
std::vector<double> rest_of(const Recording& recording) {
  const int n = recording.particle_count;
  const int dim = recording.dimension;
  const std::size_t size = at(1, 0, n, dim);
  if (recording.rest_positions.size() == size &&
      std::all_of(recording.rest_positions.begin(), recording.rest_positions.end(),
                  [](double v) { return std::isfinite(v); })) {
    return recording.rest_positions;
  }
  std::vector<double> rest(size, std::nan(""));
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < recording.frame_count(); ++k) {
      const double* p = observed_point(recording, k, i);
      if (!finite_point(p, dim)) continue;
      std::copy(p, p + dim, rest.begin() + static_cast<std::ptrdiff_t>(at(0, i, n, dim)));
      break;
    }
  }
  return rest;
}

// Root mean square distance of the rest positions from their centroid; 1 when degenerate.
double object_size(const Recording& recording) {
  const std::vector<double> rest = rest_of(recording);
  const int dim = recording.dimension;
  std::vector<double> centroid(static_cast<std::size_t>(dim), 0.0);
  int count = 0;
  for (int i = 0; i < recording.particle_count; ++i) {
    const double* p = rest.data() + at(0, i, recording.particle_count, dim);
    if (!finite_point(p, dim)) continue;
    for (int d = 0; d < dim; ++d) centroid[static_cast<std::size_t>(d)] += p[d];
    ++count;
  }
  if (count == 0) return 1.0;
  for (double& c : centroid) c /= count;
  double sum = 0;
  for (int i = 0; i < recording.particle_count; ++i) {
    const double* p = rest.data() + at(0, i, recording.particle_count, dim);
    if (finite_point(p, dim)) sum += squared(p, centroid.data(), dim);
  }
  const double size = std::sqrt(sum / count);
  return size > 0 && std::isfinite(size) ? size : 1.0;
}

// Frame after which the driven particles no longer load the object (see header); 0 without
// driven particles.
int unload_frame(const Recording& recording, double noise) {
  const int frames = recording.frame_count();
  const int dim = recording.dimension;
  int unload = 0;
  for (int id : driven_ids(recording)) {
    std::vector<int> driven_frames;
    int last_active = -1;
    for (int k = 0; k < frames; ++k) {
      if (!driven_at(recording, id, recording.frame_times_s[static_cast<std::size_t>(k)])) continue;
      last_active = k;
      if (finite_point(observed_point(recording, k, id), dim)) driven_frames.push_back(k);
    }
    if (driven_frames.empty()) continue;
    const std::size_t tail = std::min<std::size_t>(kRestFrames, driven_frames.size());
    std::vector<double> final_position(static_cast<std::size_t>(dim), 0.0);
    for (std::size_t j = driven_frames.size() - tail; j < driven_frames.size(); ++j) {
      const double* p = observed_point(recording, driven_frames[j], id);
      for (int d = 0; d < dim; ++d) final_position[static_cast<std::size_t>(d)] += p[d] / static_cast<double>(tail);
    }
    double travel = 0;
    for (int k : driven_frames)
      travel = std::max(travel, std::sqrt(squared(observed_point(recording, k, id), final_position.data(), dim)));
    const double threshold = std::max(3.0 * noise * std::sqrt(dim), 0.01 * travel);
    int settled = driven_frames.front();
    for (int k : driven_frames) {
      if (std::sqrt(squared(observed_point(recording, k, id), final_position.data(), dim)) > threshold) settled = k + 1;
    }
    if (last_active < frames - 1) settled = std::max(settled, last_active + 1);
    unload = std::max(unload, settled);
  }
  return unload;
}

// Velocity of particle `id` at frame k of a frame-major array: least-squares slope over its
// finite samples in frames k-2..k+2 on real times (noise std about s / (3.2 dt), a third of a
// frame difference's). False when fewer than two samples span a positive time.
bool velocity_at(const std::vector<double>& positions, const Recording& recording, int k, int id,
                 std::vector<double>& out) {
  const int n = recording.particle_count;
  const int dim = recording.dimension;
  const int first = std::max(0, k - kVelocityHalfWindow);
  const int last = std::min(recording.frame_count() - 1, k + kVelocityHalfWindow);
  double t_mean = 0;
  int count = 0;
  for (int j = first; j <= last; ++j) {
    if (!finite_point(positions.data() + at(j, id, n, dim), dim)) continue;
    t_mean += recording.frame_times_s[static_cast<std::size_t>(j)];
    ++count;
  }
  if (count < 2) return false;
  t_mean /= count;
  double stt = 0;
  out.assign(static_cast<std::size_t>(dim), 0.0);
  for (int j = first; j <= last; ++j) {
    const double* p = positions.data() + at(j, id, n, dim);
    if (!finite_point(p, dim)) continue;
    const double dt = recording.frame_times_s[static_cast<std::size_t>(j)] - t_mean;
    stt += dt * dt;
    for (int d = 0; d < dim; ++d) out[static_cast<std::size_t>(d)] += dt * p[d];
  }
  if (!(stt > 0)) return false;
  for (double& v : out) v /= stt;
  return true;
}

}  // namespace

// ---------------------------------------------------------------------------------- locate

Location locate_mismatch(const ResidualField& field, const std::vector<double>& frame_times_s, double noise_std,
                         const LocateOptions& options) {
  Location location;
  if (field.particle_count == 0 || field.frame_count == 0) return location;
  if (frame_times_s.size() != static_cast<std::size_t>(field.frame_count)) {
    throw std::invalid_argument("locate_mismatch: frame_times_s needs one entry per frame");
  }
  const int dim = field.dimension;
  double largest = 0;
  for (double r : field.residual) {
    if (std::isfinite(r)) largest = std::max(largest, std::abs(r));
  }
  const double noise = floored_noise(noise_std, largest);
  const double noise_ms = dim * noise * noise;

  const std::vector<double> rms = particle_rms(field);
  const std::vector<int> samples = particle_samples(field);
  std::vector<double> excess(rms.size(), 0.0);
  std::vector<int> candidates;
  double total_excess = 0;
  for (std::size_t i = 0; i < rms.size(); ++i) {
    const double ms = rms[i] * rms[i];
    excess[i] = std::max(0.0, ms - noise_ms) * samples[i];
    total_excess += excess[i];
    if (clearly_above(ms, samples[i], dim, noise, options.min_ratio, options.z))
      candidates.push_back(static_cast<int>(i));
  }
  if (candidates.empty()) return location;
  std::stable_sort(candidates.begin(), candidates.end(), [&](int a, int b) {
    return excess[static_cast<std::size_t>(a)] > excess[static_cast<std::size_t>(b)];
  });
  double covered = 0;
  for (int id : candidates) {
    location.particles.push_back(id);
    covered += excess[static_cast<std::size_t>(id)];
    if (covered >= options.energy_fraction * total_excess) break;
  }
  std::sort(location.particles.begin(), location.particles.end());

  // Time window over the located particles.
  const std::vector<unsigned char> mask = location_mask(location, field.particle_count);
  const std::vector<double> frame = frame_rms(field, &mask);
  const std::vector<int> frame_count = frame_samples(field, &mask);
  const int frames = field.frame_count;
  const int bridge = std::max(0, options.bridge_frames);
  int best_first = -1;
  int best_last = -1;
  double best_energy = -1;
  int run_first = -1;
  int run_last = -1;
  double run_energy = 0;
  auto close_run = [&] {
    if (run_first >= 0 && run_energy > best_energy) {
      best_first = run_first;
      best_last = run_last;
      best_energy = run_energy;
    }
  };
  for (int k = 0; k < frames; ++k) {
    const auto sk = static_cast<std::size_t>(k);
    const double ms = frame[sk] * frame[sk];
    if (!clearly_above(ms, frame_count[sk], dim, noise, options.min_ratio, options.z)) continue;
    if (run_first >= 0 && k - run_last - 1 > bridge) {
      close_run();
      run_first = -1;
    }
    if (run_first < 0) {
      run_first = k;
      run_energy = 0;
    }
    run_last = k;
    run_energy += (ms - noise_ms) * frame_count[sk];
  }
  close_run();
  if (best_first < 0) {
    for (int k = 0; k < frames; ++k) {
      if (frame_count[static_cast<std::size_t>(k)] == 0) continue;
      if (best_first < 0) best_first = k;
      best_last = k;
    }
  }
  if (best_first >= 0) {
    location.t_start = frame_times_s[static_cast<std::size_t>(best_first)];
    location.t_end = frame_times_s[static_cast<std::size_t>(best_last)];
  }
  return location;
}

// ------------------------------------------------------------------------------ signatures

double persistence_after_unload(const Recording& recording, const ResidualField& field, const Location& location,
                                double noise_std) {
  check_field(recording, field);
  const std::vector<unsigned char> mask = location_mask(location, recording.particle_count);
  const int frames = field.frame_count;
  if (!any_set(mask) || frames == 0) return 0.0;
  const int dim = recording.dimension;
  const double noise = floored_noise(noise_std, object_size(recording));
  const double noise_ms = dim * noise * noise;
  const int unload = unload_frame(recording, noise);
  if (unload >= frames) return 0.0;
  const int after = frames - unload;
  const int tail = std::max(1, static_cast<int>(std::ceil(kTailFraction * after)));

  const std::vector<double> rms = frame_rms(field, &mask);
  const std::vector<int> count = frame_samples(field, &mask);
  const LocateOptions gate;
  // Peak: largest mean square pooled over 5 consecutive frames, so one noisy frame cannot set it.
  double peak = 0;
  for (int k = 0; k < frames; ++k) {
    double sum = 0;
    double pairs = 0;
    for (int j = std::max(0, k - kPeakHalfWindow); j <= std::min(frames - 1, k + kPeakHalfWindow); ++j) {
      const auto sj = static_cast<std::size_t>(j);
      sum += rms[sj] * rms[sj] * count[sj];
      pairs += count[sj];
    }
    if (!(pairs > 0)) continue;
    const double ms = sum / pairs;
    if (clearly_above(ms, pairs, dim, noise, gate.min_ratio, gate.z)) peak = std::max(peak, ms - noise_ms);
  }
  if (!(peak > 0)) return 0.0;
  double sum = 0;
  double pairs = 0;
  for (int k = frames - tail; k < frames; ++k) {
    const auto sk = static_cast<std::size_t>(k);
    sum += rms[sk] * rms[sk] * count[sk];
    pairs += count[sk];
  }
  if (!(pairs > 0)) return 0.0;
  const double tail_ms = sum / pairs;
  if (!clearly_above(tail_ms, pairs, dim, noise, 1.0, kSmallSampleSignificance)) return 0.0;
  return std::clamp(std::sqrt((tail_ms - noise_ms) / peak), 0.0, 1.0);
}

double velocity_correlation(const Recording& recording, const ResidualField& field, const Location& location) {
  check_field(recording, field);
  const std::vector<unsigned char> mask = location_mask(location, recording.particle_count);
  const std::vector<int> drivers = driven_ids(recording);
  if (!any_set(mask) || drivers.empty()) return 0.0;
  const int dim = recording.dimension;
  const auto udim = static_cast<std::size_t>(dim);
  // Per usable frame: the mean driver velocity (0 when no driver is active) and the mean
  // residual of the located particles.
  std::vector<Eigen::VectorXd> velocity;
  std::vector<Eigen::VectorXd> residual;
  std::vector<double> v;
  for (int k = 0; k < field.frame_count; ++k) {
    const double t = recording.frame_times_s[static_cast<std::size_t>(k)];
    Eigen::VectorXd mean_v = Eigen::VectorXd::Zero(dim);
    int active = 0;
    bool usable = true;
    for (int id : drivers) {
      if (!driven_at(recording, id, t)) continue;
      if (!velocity_at(recording.positions, recording, k, id, v)) {
        usable = false;
        break;
      }
      for (std::size_t d = 0; d < udim; ++d) mean_v(static_cast<Eigen::Index>(d)) += v[d];
      ++active;
    }
    if (!usable) continue;
    Eigen::VectorXd mean_r = Eigen::VectorXd::Zero(dim);
    int located = 0;
    for (int i = 0; i < field.particle_count; ++i) {
      if (mask[static_cast<std::size_t>(i)] == 0 || !field.observed(k, i)) continue;
      for (int d = 0; d < dim; ++d) mean_r(d) += field.at(k, i)[d];
      ++located;
    }
    if (located == 0) continue;
    velocity.push_back(active > 0 ? Eigen::VectorXd(mean_v / active) : mean_v);
    residual.push_back(mean_r / located);
  }
  const auto samples = static_cast<double>(velocity.size());
  if (samples < dim + 3) return 0.0;
  Eigen::VectorXd v_mean = Eigen::VectorXd::Zero(dim);
  Eigen::VectorXd r_mean = Eigen::VectorXd::Zero(dim);
  for (std::size_t j = 0; j < velocity.size(); ++j) {
    v_mean += velocity[j] / samples;
    r_mean += residual[j] / samples;
  }
  // The driver's main direction of motion.
  Eigen::MatrixXd v_cov = Eigen::MatrixXd::Zero(dim, dim);
  for (const Eigen::VectorXd& vj : velocity) v_cov += (vj - v_mean) * (vj - v_mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> main_axis(v_cov);
  if (main_axis.info() != Eigen::Success) return 0.0;
  const Eigen::VectorXd u = main_axis.eigenvectors().col(dim - 1);
  // Multiple correlation of the driver speed along u with the residual vector.
  double sxx = 0;
  Eigen::VectorXd sxy = Eigen::VectorXd::Zero(dim);
  Eigen::MatrixXd syy = Eigen::MatrixXd::Zero(dim, dim);
  for (std::size_t j = 0; j < velocity.size(); ++j) {
    const double x = (velocity[j] - v_mean).dot(u);
    const Eigen::VectorXd y = residual[j] - r_mean;
    sxx += x * x;
    sxy += x * y;
    syy += y * y.transpose();
  }
  const double ridge = 1e-12 * syy.trace();
  if (!(sxx > 0) || !(ridge > 0)) return 0.0;
  syy.diagonal().array() += ridge;
  const double r2 = sxy.dot(syy.ldlt().solve(sxy)) / sxx;
  if (!std::isfinite(r2) || !(r2 > 0)) return 0.0;
  // Under no correlation samples * R^2 is about chi-square with `dim` degrees of freedom.
  if (!(samples * r2 > kChiSquareGate + kChiSquarePerDof * dim)) return 0.0;
  return std::min(1.0, std::sqrt(r2));
}

double support_motion(const Recording& recording, double noise_std) {
  check_recording(recording);
  const int dim = recording.dimension;
  const double noise = floored_noise(noise_std, object_size(recording));
  const double noise_ms = dim * noise * noise;
  const double noise4 = noise * noise * noise * noise;
  double sum = 0;
  double expected = 0;
  double count = 0;
  // Per fixed particle: (samples, rest frames), for the variance of the mean square.
  std::vector<std::pair<double, double>> tracks;
  for (int id : recording.fixed) {
    if (id < 0 || id >= recording.particle_count) continue;
    std::vector<int> seen;
    for (int k = 0; k < recording.frame_count(); ++k) {
      if (finite_point(observed_point(recording, k, id), dim)) seen.push_back(k);
    }
    if (seen.empty()) continue;
    const std::size_t m = std::min<std::size_t>(kSupportRestFrames, seen.size());
    std::vector<double> rest(static_cast<std::size_t>(dim), 0.0);
    for (std::size_t j = 0; j < m; ++j) {
      const double* p = observed_point(recording, seen[j], id);
      for (int d = 0; d < dim; ++d) rest[static_cast<std::size_t>(d)] += p[d] / static_cast<double>(m);
    }
    const double inv_m = 1.0 / static_cast<double>(m);
    for (std::size_t j = 0; j < seen.size(); ++j) {
      sum += squared(observed_point(recording, seen[j], id), rest.data(), dim);
      // A sample inside the rest average shares its noise: E|x - rest|^2 = dim s^2 (1 - 1/m).
      expected += noise_ms * (j < m ? 1.0 - inv_m : 1.0 + inv_m);
      count += 1;
    }
    tracks.emplace_back(static_cast<double>(seen.size()), static_cast<double>(m));
  }
  if (!(count > 0) || !(expected > 0)) return 0.0;
  const double ms = sum / count;
  const double expected_ms = expected / count;
  // Variance of ms under noise alone: the white part, plus the rest error e_i shared by all
  // n_i samples of a particle (|e_i|^2 and the cross term n_k . e_i).
  double variance = 2.0 * dim * noise4 / count;
  for (const auto& [samples, m] : tracks) {
    const double share = samples / count;
    variance += share * share * 2.0 * dim * noise4 / (m * m) + 4.0 * samples * dim * noise4 / (m * count * count);
  }
  if (!(ms > expected_ms + kSmallSampleSignificance * std::sqrt(variance))) return 0.0;
  return std::sqrt(ms - expected_ms) / std::sqrt(noise_ms);
}

UniformDrift uniform_drift(const Recording& recording, const ResidualField& field, double noise_std) {
  check_field(recording, field);
  const int n = recording.particle_count;
  const int dim = recording.dimension;
  UniformDrift out;
  out.direction.assign(static_cast<std::size_t>(dim), 0.0);
  std::vector<int> supports;
  for (int id : recording.fixed) {
    if (id >= 0 && id < n) supports.push_back(id);
  }
  if (supports.empty()) supports = driven_ids(recording);
  if (supports.empty() || field.frame_count == 0) return out;

  const std::vector<double> rest = rest_of(recording);
  std::vector<double> distance(static_cast<std::size_t>(n), 0.0);
  for (int i = 0; i < n; ++i) {
    const double* p = rest.data() + at(0, i, n, dim);
    double nearest = HUGE_VAL;
    for (int s : supports) {
      const double* q = rest.data() + at(0, s, n, dim);
      if (finite_point(p, dim) && finite_point(q, dim)) nearest = std::min(nearest, std::sqrt(squared(p, q, dim)));
    }
    distance[static_cast<std::size_t>(i)] = std::isfinite(nearest) ? nearest : 0.0;
  }

  const double noise = floored_noise(noise_std, object_size(recording));
  Eigen::MatrixXd scatter = Eigen::MatrixXd::Zero(dim, dim);
  Eigen::VectorXd orientation = Eigen::VectorXd::Zero(dim);
  double total = 0;
  double pairs = 0;
  double frames_used = 0;
  for (int k = 0; k < field.frame_count; ++k) {
    Eigen::VectorXd weighted = Eigen::VectorXd::Zero(dim);
    double weight = 0;
    for (int i = 0; i < n; ++i) {
      if (!field.observed(k, i)) continue;
      const double* r = field.at(k, i);
      const double di = distance[static_cast<std::size_t>(i)];
      for (int d = 0; d < dim; ++d) {
        total += r[d] * r[d];
        weighted(d) += di * r[d];
      }
      pairs += 1;
      weight += di * di;
    }
    if (!(weight > 0)) continue;
    // Least-squares amplitude vector of this frame is weighted / weight; its energy along u is
    // (weighted . u)^2 / weight.
    scatter += weighted * weighted.transpose() / weight;
    orientation += weighted;
    frames_used += 1;
  }
  if (!(pairs > 0) || !(frames_used > 0)) return out;
  if (!clearly_above(total / pairs, pairs, dim, noise, 1.0, kSignificance)) return out;
  const double total_excess = total - pairs * dim * noise * noise;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(scatter);
  if (solver.info() != Eigen::Success) return out;
  const double explained = solver.eigenvalues()(dim - 1);
  // Largest eigenvalue of a white-noise Wishart(dim, frames) matrix with scale s^2.
  const double noise_explained = noise * noise * std::pow(std::sqrt(frames_used) + std::sqrt(dim), 2.0);
  const double fraction = (explained - noise_explained) / total_excess;
  if (!(fraction > 0) || !std::isfinite(fraction)) return out;
  out.fraction = std::min(1.0, fraction);
  Eigen::VectorXd u = solver.eigenvectors().col(dim - 1);
  if (orientation.dot(u) < 0) u = -u;
  for (int d = 0; d < dim; ++d) out.direction[static_cast<std::size_t>(d)] = u(d);
  return out;
}

double load_sign_change(const Recording& recording, const ResidualField& field, const Location& location,
                        double noise_std) {
  check_field(recording, field);
  const std::vector<unsigned char> mask = location_mask(location, recording.particle_count);
  const std::vector<int> drivers = driven_ids(recording);
  if (!any_set(mask) || drivers.empty() || field.frame_count == 0) return 0.0;
  const int n = recording.particle_count;
  const int dim = recording.dimension;
  const auto udim = static_cast<std::size_t>(dim);
  const std::vector<double> rest = rest_of(recording);
  const int frames = field.frame_count;
  std::vector<double> load(static_cast<std::size_t>(frames) * udim, 0.0);
  std::vector<unsigned char> loaded(static_cast<std::size_t>(frames), 0);
  double peak = 0;
  int peak_frame = -1;
  for (int k = 0; k < frames; ++k) {
    const double t = recording.frame_times_s[static_cast<std::size_t>(k)];
    int active = 0;
    double* lk = load.data() + static_cast<std::size_t>(k) * udim;
    for (int id : drivers) {
      const double* p = observed_point(recording, k, id);
      const double* r0 = rest.data() + at(0, id, n, dim);
      if (!driven_at(recording, id, t) || !finite_point(p, dim) || !finite_point(r0, dim)) continue;
      for (int d = 0; d < dim; ++d) lk[d] += p[d] - r0[d];
      ++active;
    }
    if (active == 0) continue;
    double amplitude = 0;
    for (std::size_t d = 0; d < udim; ++d) {
      lk[d] /= active;
      amplitude += lk[d] * lk[d];
    }
    amplitude = std::sqrt(amplitude);
    loaded[static_cast<std::size_t>(k)] = 1;
    if (amplitude > peak) {
      peak = amplitude;
      peak_frame = k;
    }
  }
  const double noise = floored_noise(noise_std, object_size(recording));
  if (peak_frame < 0 || !(peak > kSignificance * noise * std::sqrt(dim))) return 0.0;
  std::vector<double> direction(
      load.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(peak_frame) * udim),
      load.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(peak_frame + 1) * udim));
  for (double& c : direction) c /= peak;

  double sum_small = 0;
  double sum_large = 0;
  double count_small = 0;
  double count_large = 0;
  for (int k = 0; k < frames; ++k) {
    if (loaded[static_cast<std::size_t>(k)] == 0) continue;
    const double* lk = load.data() + static_cast<std::size_t>(k) * udim;
    double amplitude = 0;
    for (int d = 0; d < dim; ++d) amplitude += lk[d] * lk[d];
    amplitude = std::sqrt(amplitude);
    const bool large = amplitude > 0.75 * peak;
    const bool small = amplitude > 0.1 * peak && amplitude <= 0.5 * peak;
    if (!large && !small) continue;
    for (int i = 0; i < n; ++i) {
      if (mask[static_cast<std::size_t>(i)] == 0 || !field.observed(k, i)) continue;
      double along = 0;
      for (int d = 0; d < dim; ++d) along += field.at(k, i)[d] * direction[static_cast<std::size_t>(d)];
      (large ? sum_large : sum_small) += along;
      (large ? count_large : count_small) += 1;
    }
  }
  if (!(count_small > 0) || !(count_large > 0)) return 0.0;
  const double mean_small = sum_small / count_small;
  const double mean_large = sum_large / count_large;
  const bool significant = std::abs(mean_small) > kSignificance * noise / std::sqrt(count_small) &&
                           std::abs(mean_large) > kSignificance * noise / std::sqrt(count_large);
  if (!significant || !(mean_small * mean_large < 0)) return 0.0;
  return std::min(std::abs(mean_small), std::abs(mean_large)) / std::max(std::abs(mean_small), std::abs(mean_large));
}

double time_shift(const Recording& recording, const std::vector<double>& simulated, const Location& location,
                  double noise_std) {
  check_recording(recording);
  if (simulated.size() != recording.positions.size())
    throw std::invalid_argument("time_shift: simulated size differs from positions");
  const int n = recording.particle_count;
  const int dim = recording.dimension;
  const int frames = recording.frame_count();
  location_mask(location, n);  // validates the ids
  std::vector<int> ids = location.particles;
  if (ids.empty()) ids = driven_ids(recording);
  if (ids.empty()) {
    ids.resize(static_cast<std::size_t>(n));
    std::iota(ids.begin(), ids.end(), 0);
  }
  if (frames < 3 || ids.empty()) return 0.0;
  const auto udim = static_cast<std::size_t>(dim);
  const std::size_t per_frame = ids.size() * udim;
  // Velocities (5-frame slopes) [frame][particle of ids][axis], NaN where unavailable.
  auto velocities = [&](const std::vector<double>& positions) {
    std::vector<double> v(static_cast<std::size_t>(frames) * per_frame, std::nan(""));
    std::vector<double> one;
    for (int k = 0; k < frames; ++k) {
      for (std::size_t j = 0; j < ids.size(); ++j) {
        if (!velocity_at(positions, recording, k, ids[j], one)) continue;
        std::copy(one.begin(), one.end(),
                  v.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(k) * per_frame + j * udim));
      }
    }
    return v;
  };
  const std::vector<double> observed_v = velocities(recording.positions);
  const std::vector<double> simulated_v = velocities(simulated);
  const int max_lag = std::max(1, frames / 4);
  std::vector<double> correlation(static_cast<std::size_t>(2 * max_lag + 1), 0.0);
  std::vector<double> samples(correlation.size(), 0.0);
  std::vector<double> products(correlation.size(), 0.0);
  for (int lag = -max_lag; lag <= max_lag; ++lag) {
    double dot = 0;
    double eo = 0;
    double es = 0;
    double count = 0;
    for (int k = std::max(0, -lag); k < frames && k + lag < frames; ++k) {
      const double* o = observed_v.data() + static_cast<std::size_t>(k + lag) * per_frame;
      const double* s = simulated_v.data() + static_cast<std::size_t>(k) * per_frame;
      for (std::size_t j = 0; j < ids.size(); ++j) {
        if (!finite_point(o + j * udim, dim) || !finite_point(s + j * udim, dim)) continue;
        for (std::size_t d = 0; d < udim; ++d) {
          dot += o[j * udim + d] * s[j * udim + d];
          eo += o[j * udim + d] * o[j * udim + d];
          es += s[j * udim + d] * s[j * udim + d];
        }
        count += dim;
      }
    }
    const auto slot = static_cast<std::size_t>(lag + max_lag);
    if (eo > 0 && es > 0) correlation[slot] = dot / std::sqrt(eo * es);
    samples[slot] = count;
    products[slot] = dot;
  }
  const auto best =
      static_cast<std::size_t>(std::max_element(correlation.begin(), correlation.end()) - correlation.begin());
  const double peak = correlation[best];
  if (!(peak > 0) || !(peak * std::sqrt(samples[best]) > kSignificance)) return 0.0;
  std::vector<double> steps;
  for (int k = 0; k + 1 < frames; ++k) {
    steps.push_back(recording.frame_times_s[static_cast<std::size_t>(k + 1)] -
                    recording.frame_times_s[static_cast<std::size_t>(k)]);
  }
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  const double step = steps[steps.size() / 2];
  const int best_lag = static_cast<int>(best) - max_lag;
  if (best_lag != 0) {
    // A non-zero lag must beat lag 0 by kSignificance standard deviations of the noise part of
    // products[best] - products[0] = sum_m n_v(m) . (s(m - lag) - s(m)), where n_v is the
    // position noise passed through the 5-frame slope filter (weights i / (10 step)).
    const double noise = floored_noise(noise_std, object_size(recording));
    double variance = 0;
    std::vector<double> w(static_cast<std::size_t>(frames));
    for (std::size_t j = 0; j < ids.size(); ++j) {
      for (std::size_t d = 0; d < udim; ++d) {
        auto sim_at = [&](int m) {
          if (m < 0 || m >= frames) return 0.0;
          const double value = simulated_v[static_cast<std::size_t>(m) * per_frame + j * udim + d];
          return std::isfinite(value) ? value : 0.0;
        };
        for (int m = 0; m < frames; ++m) w[static_cast<std::size_t>(m)] = sim_at(m - best_lag) - sim_at(m);
        for (int q = -kVelocityHalfWindow; q < frames + kVelocityHalfWindow; ++q) {
          double g = 0;
          for (int i = -kVelocityHalfWindow; i <= kVelocityHalfWindow; ++i) {
            if (q - i >= 0 && q - i < frames) g += i * w[static_cast<std::size_t>(q - i)];
          }
          g /= 10.0 * step;
          variance += g * g;
        }
      }
    }
    variance *= noise * noise;
    const double gain = products[best] - products[static_cast<std::size_t>(max_lag)];
    if (!(gain > kSignificance * std::sqrt(variance))) return 0.0;
  }
  double offset = 0;
  if (best > 0 && best + 1 < correlation.size()) {
    const double before = correlation[best - 1];
    const double after = correlation[best + 1];
    const double curvature = before - 2.0 * peak + after;
    if (curvature < 0) offset = std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5);
  }
  const double lag_s = (best_lag + offset) * step;
  return std::isfinite(lag_s) ? lag_s : 0.0;
}

std::map<std::string, double> residual_signatures(const Recording& recording, const std::vector<double>& simulated,
                                                  const ResidualField& field, const Location& location,
                                                  double noise_std) {
  std::map<std::string, double> out;
  out["persistence_after_unload"] = persistence_after_unload(recording, field, location, noise_std);
  out["velocity_correlation"] = velocity_correlation(recording, field, location);
  out["support_motion"] = support_motion(recording, noise_std);
  const UniformDrift drift = uniform_drift(recording, field, noise_std);
  out["uniform_drift"] = drift.fraction;
  const char* axes[] = {"uniform_drift_x", "uniform_drift_y", "uniform_drift_z"};
  for (std::size_t d = 0; d < drift.direction.size() && d < 3; ++d) out[axes[d]] = drift.direction[d];
  out["load_sign_change"] = load_sign_change(recording, field, location, noise_std);
  out["time_shift"] = time_shift(recording, simulated, location, noise_std);
  return out;
}

std::map<std::string, double> residual_signatures(const Recording& recording, const std::vector<double>& simulated,
                                                  double noise_std) {
  check_recording(recording);
  const ResidualField field =
      make_residual_field(recording.positions, simulated, recording.particle_count, recording.dimension);
  const Location location = locate_mismatch(field, recording.frame_times_s, noise_std);
  return residual_signatures(recording, simulated, field, location, noise_std);
}

}  // namespace pliant::host
