#include "pliant/host/diagnose/diagnose.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "pliant/host/diagnose/effects.hpp"
#include "pliant/host/diagnose/fem_diagnose.hpp"
#include "pliant/host/diagnose/holdout.hpp"
#include "pliant/host/diagnose/locate.hpp"
#include "pliant/host/diagnose/model_run.hpp"
#include "pliant/host/diagnose/noise_floor.hpp"
#include "pliant/host/diagnose/residual_field.hpp"

namespace pliant::host {
namespace {

constexpr int kMinFrames = 10;
constexpr double kMinImprovement = 0.3;   // held-out rms must fall by 30 % ...
constexpr double kMinBicGain = 10.0;      // ... with "very strong" evidence (Kass-Raftery) ...
constexpr double kMinSignificance = 3.0;  // ... and a parameter 3 std from its null
constexpr double kMinMisfit = 1.5;        // baseline held-out rms / noise rms worth explaining
constexpr double kUnknownMisfit = 5.0;    // unexplained misfit that is reported as `unknown`

// Sums of squared Euclidean residuals over the compared pairs of fitting and held-out frames.
struct Score {
  double fit_rss = 0;
  long fit_pairs = 0;
  double held_rss = 0;
  long held_pairs = 0;
  double fit_rms() const { return fit_pairs > 0 ? std::sqrt(fit_rss / static_cast<double>(fit_pairs)) : 0.0; }
  double held_rms() const { return held_pairs > 0 ? std::sqrt(held_rss / static_cast<double>(held_pairs)) : 0.0; }
};

class Scorer {
 public:
  Scorer(const Recording& recording, std::vector<unsigned char> pairs, std::vector<unsigned char> held_out)
      : recording_(recording), pairs_(std::move(pairs)), held_out_(std::move(held_out)) {}

  Score score(const std::vector<double>& simulated) const {
    Score s;
    const int n = recording_.particle_count;
    const int dim = recording_.dimension;
    for (int k = 0; k < recording_.frame_count(); ++k) {
      const bool held = held_out_[static_cast<std::size_t>(k)] != 0;
      for (int i = 0; i < n; ++i) {
        const std::size_t pair =
            static_cast<std::size_t>(k) * static_cast<std::size_t>(n) + static_cast<std::size_t>(i);
        if (pairs_[pair] == 0) continue;
        double squared = 0;
        for (int d = 0; d < dim; ++d) {
          const double r = simulated[pair * static_cast<std::size_t>(dim) + static_cast<std::size_t>(d)] -
                           recording_.position(k, i, d);
          squared += r * r;
        }
        if (!std::isfinite(squared)) continue;
        if (held) {
          s.held_rss += squared;
          ++s.held_pairs;
        } else {
          s.fit_rss += squared;
          ++s.fit_pairs;
        }
      }
    }
    return s;
  }

  /// Residual scalars on fitting pairs, in a fixed order (for the Jacobian).
  Eigen::VectorXd fit_residuals(const std::vector<double>& simulated) const {
    std::vector<double> values;
    const int n = recording_.particle_count;
    const int dim = recording_.dimension;
    for (int k = 0; k < recording_.frame_count(); ++k) {
      if (held_out_[static_cast<std::size_t>(k)] != 0) continue;
      for (int i = 0; i < n; ++i) {
        const std::size_t pair =
            static_cast<std::size_t>(k) * static_cast<std::size_t>(n) + static_cast<std::size_t>(i);
        if (pairs_[pair] == 0) continue;
        for (int d = 0; d < dim; ++d) {
          const double r = simulated[pair * static_cast<std::size_t>(dim) + static_cast<std::size_t>(d)] -
                           recording_.position(k, i, d);
          values.push_back(std::isfinite(r) ? r : 0.0);
        }
      }
    }
    return Eigen::Map<Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
  }

  const std::vector<unsigned char>& held_out() const { return held_out_; }

 private:
  const Recording& recording_;
  std::vector<unsigned char> pairs_;
  std::vector<unsigned char> held_out_;
};

struct Fit {
  std::vector<double> u;       // search coordinates: [0] msm_beta, then the effect's
  std::vector<double> values;  // physical effect parameter values
  std::vector<double> std;     // one std per effect parameter (inf when not identifiable)
  double beta = 0;
  double beta_std = 0;
  Score score;
  std::vector<double> simulated;
  double bic = 0;
};

// Golden-section search of f on [lo, hi] to `tolerance`, starting from a known best point.
template <typename F>
double golden(F&& f, double lo, double hi, double tolerance, double& best_x, double& best_value) {
  const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = hi - ratio * (hi - lo);
  double b = lo + ratio * (hi - lo);
  double fa = f(a);
  double fb = f(b);
  auto keep = [&](double x, double v) {
    if (v < best_value) {
      best_value = v;
      best_x = x;
    }
  };
  keep(a, fa);
  keep(b, fb);
  while (hi - lo > tolerance) {
    if (fa <= fb) {
      hi = b;
      b = a;
      fb = fa;
      a = hi - ratio * (hi - lo);
      fa = f(a);
      keep(a, fa);
    } else {
      lo = a;
      a = b;
      fa = fb;
      b = lo + ratio * (hi - lo);
      fb = f(b);
      keep(b, fb);
    }
  }
  return best_x;
}

// Per-patch stiffness split in two groups by msm_beta: the split that maximises the
// between-group variance (particle-weighted, Otsu's criterion). The larger group is the bulk.
struct PatchSplit {
  std::vector<std::size_t> region;  // patch indices of the smaller group
  double bulk_beta = 0;
  double region_beta = 0;
};

PatchSplit split_patches(const std::vector<std::vector<int>>& patches, const std::vector<double>& beta) {
  std::vector<std::size_t> order;
  for (std::size_t k = 0; k < patches.size() && k < beta.size(); ++k) order.push_back(k);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return beta[a] < beta[b]; });
  double total_weight = 0;
  double total_sum = 0;
  for (std::size_t k : order) {
    total_weight += static_cast<double>(patches[k].size());
    total_sum += static_cast<double>(patches[k].size()) * beta[k];
  }
  PatchSplit best;
  best.bulk_beta = total_weight > 0 ? total_sum / total_weight : 0.0;
  double best_score = -1;
  double weight = 0;
  double sum = 0;
  for (std::size_t cut = 0; cut + 1 < order.size(); ++cut) {
    weight += static_cast<double>(patches[order[cut]].size());
    sum += static_cast<double>(patches[order[cut]].size()) * beta[order[cut]];
    const double low = sum / weight;
    const double high = (total_sum - sum) / (total_weight - weight);
    const double score = weight * (total_weight - weight) * (high - low) * (high - low);
    if (score <= best_score) continue;
    best_score = score;
    const bool low_is_region = 2 * weight < total_weight;
    best.region.assign(order.begin() + (low_is_region ? 0 : static_cast<long>(cut) + 1),
                       low_is_region ? order.begin() + static_cast<long>(cut) + 1 : order.end());
    best.region_beta = low_is_region ? low : high;
    best.bulk_beta = low_is_region ? high : low;
  }
  return best;
}

class Fitter {
 public:
  Fitter(const RecordingSimulator& simulator, const Scorer& scorer, const EffectContext& context)
      : simulator_(simulator), scorer_(scorer), context_(context) {}

  ModelSettings settings(const Effect* effect, double beta, const std::vector<double>& values) const {
    ModelSettings s;
    s.msm_beta = std::clamp(beta, 0.0, 1.0);
    if (effect != nullptr) effect->apply(values, context_, s);
    return s;
  }

  std::vector<double> physical(const Effect* effect, const std::vector<double>& u) const {
    std::vector<double> values;
    if (effect == nullptr) return values;
    for (std::size_t p = 0; p < effect->parameters.size(); ++p) values.push_back(effect->parameters[p].value(u[p + 1]));
    return values;
  }

  double objective(const Effect* effect, const std::vector<double>& u) {
    ++evaluations;
    const std::vector<double> sim = simulator_.simulate(settings(effect, u[0], physical(effect, u)));
    return scorer_.score(sim).fit_rss;
  }

  // Fitting-frame residuals at search coordinates u (one simulation).
  Eigen::VectorXd residuals(const Effect* effect, const std::vector<double>& u) {
    ++evaluations;
    return scorer_.fit_residuals(simulator_.simulate(settings(effect, u[0], physical(effect, u))));
  }

  // The fit: a grid over the effect's scanned coordinates (responses flat near the null need
  // it), msm_beta profiled out at every grid point by Gauss-Newton (it trades off against
  // most effects), then bounded Levenberg-Marquardt on all coordinates from the two best grid
  // points.
  Fit fit(const Effect* effect, double start_beta) {
    std::vector<double> start(1, start_beta);
    std::vector<int> scanned;
    for (std::size_t p = 0; p < effect->parameters.size(); ++p) {
      const EffectParameter& parameter = effect->parameters[p];
      double u = 0.0;
      if (std::isfinite(parameter.null_value))
        u = parameter.coordinate(parameter.null_value);
      else if (effect->replaces_beta)
        u = parameter.coordinate(start_beta);
      start.push_back(u);
      if (parameter.scanned) scanned.push_back(static_cast<int>(p) + 1);
    }
    const bool fit_beta = !effect->replaces_beta;

    struct Seed {
      std::vector<double> u;
      double cost;
    };
    std::vector<Seed> seeds;
    const int per_axis = scanned.size() <= 1 ? 7 : (scanned.size() == 2 ? 5 : 4);
    long points = 1;
    for (std::size_t a = 0; a < scanned.size(); ++a) points *= per_axis;
    for (long index = 0; index < points; ++index) {
      std::vector<double> u = start;
      long rest = index;
      for (int c : scanned) {
        u[static_cast<std::size_t>(c)] = static_cast<double>(rest % per_axis) / (per_axis - 1);
        rest /= per_axis;
      }
      const double cost = fit_beta ? profile_beta(effect, u) : residuals(effect, u).squaredNorm();
      seeds.push_back({u, cost});
    }
    std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.cost < b.cost; });
    std::vector<double> best_u = seeds.front().u;
    double best_cost = std::numeric_limits<double>::infinity();
    const std::size_t starts = std::min<std::size_t>(seeds.size(), 2);
    for (std::size_t k = 0; k < starts; ++k) {
      std::vector<double> u = seeds[k].u;
      const double cost = levenberg_marquardt(effect, u, fit_beta);
      if (cost < best_cost) {
        best_cost = cost;
        best_u = u;
      }
    }
    return finish(effect, best_u);
  }

  // msm_beta (coordinate 0) refitted with the others held: two Gauss-Newton steps.
  double profile_beta(const Effect* effect, std::vector<double>& u) {
    Eigen::VectorXd r = residuals(effect, u);
    double cost = r.squaredNorm();
    for (int iteration = 0; iteration < 2; ++iteration) {
      const double h = u[0] + 0.01 <= 1.0 ? 0.01 : -0.01;
      std::vector<double> probe = u;
      probe[0] += h;
      const Eigen::VectorXd j = (residuals(effect, probe) - r) / h;
      const double jj = j.squaredNorm();
      if (!(jj > 0)) break;
      const double step = std::clamp(-j.dot(r) / jj, -0.3, 0.3);
      std::vector<double> trial = u;
      trial[0] = std::clamp(u[0] + step, 0.0, 1.0);
      const Eigen::VectorXd rt = residuals(effect, trial);
      const double ct = rt.squaredNorm();
      if (!(ct < cost)) break;
      u = trial;
      r = rt;
      cost = ct;
    }
    return cost;
  }

  // Bounded Levenberg-Marquardt in the unit coordinates: forward-difference Jacobian, bounds by
  // projection, coordinates held at a bound while the gradient pushes outward. Returns the
  // fitting-frame residual sum of squares at the final u.
  double levenberg_marquardt(const Effect* effect, std::vector<double>& u, bool fit_beta) {
    const int p = static_cast<int>(u.size());
    Eigen::VectorXd r = residuals(effect, u);
    double cost = r.squaredNorm();
    double lambda = 1e-2;
    for (int iteration = 0; iteration < 25; ++iteration) {
      Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(r.size(), p);
      for (int c = fit_beta ? 0 : 1; c < p; ++c) {
        const double h = u[static_cast<std::size_t>(c)] + 0.005 <= 1.0 ? 0.005 : -0.005;
        std::vector<double> probe = u;
        probe[static_cast<std::size_t>(c)] += h;
        jacobian.col(c) = (residuals(effect, probe) - r) / h;
      }
      const Eigen::VectorXd gradient = jacobian.transpose() * r;
      std::vector<int> free;
      for (int c = fit_beta ? 0 : 1; c < p; ++c) {
        const double uc = u[static_cast<std::size_t>(c)];
        const double gc = gradient(c);
        if ((uc <= 0.0 && gc > 0) || (uc >= 1.0 && gc < 0)) continue;
        if (jacobian.col(c).squaredNorm() > 0) free.push_back(c);
      }
      if (free.empty()) break;
      const int m = static_cast<int>(free.size());
      Eigen::MatrixXd normal(m, m);
      Eigen::VectorXd g(m);
      for (int a = 0; a < m; ++a) {
        g(a) = gradient(free[static_cast<std::size_t>(a)]);
        for (int b = 0; b < m; ++b) {
          normal(a, b) =
              jacobian.col(free[static_cast<std::size_t>(a)]).dot(jacobian.col(free[static_cast<std::size_t>(b)]));
        }
      }
      bool accepted = false;
      double new_cost = cost;
      for (int attempt = 0; attempt < 8 && !accepted; ++attempt) {
        Eigen::MatrixXd damped = normal;
        for (int a = 0; a < m; ++a) damped(a, a) += lambda * std::max(normal(a, a), 1e-12);
        const Eigen::VectorXd delta = damped.ldlt().solve(-g);
        std::vector<double> trial = u;
        for (int a = 0; a < m; ++a) {
          double& value = trial[static_cast<std::size_t>(free[static_cast<std::size_t>(a)])];
          value = std::clamp(value + (std::isfinite(delta(a)) ? delta(a) : 0.0), 0.0, 1.0);
        }
        if (trial == u) break;
        const Eigen::VectorXd rt = residuals(effect, trial);
        const double ct = rt.squaredNorm();
        if (ct < cost) {
          accepted = true;
          new_cost = ct;
          u = trial;
          r = rt;
          lambda = std::max(lambda / 4.0, 1e-7);
        } else {
          lambda *= 6.0;
        }
      }
      if (!accepted) break;
      const double gain = cost - new_cost;
      cost = new_cost;
      if (gain < 1e-5 * cost) break;
    }
    return cost;
  }

  Fit finish(const Effect* effect, const std::vector<double>& u) {
    Fit f;
    f.u = u;
    f.beta = u[0];
    f.values = physical(effect, u);
    f.simulated = simulator_.simulate(settings(effect, f.beta, f.values));
    f.score = scorer_.score(f.simulated);
    // Uncertainty: J = d residual / d parameter by central differences; cov = s^2 (J^T J)^-1.
    const Eigen::VectorXd r0 = scorer_.fit_residuals(f.simulated);
    const int p = static_cast<int>(u.size());
    const int first = effect != nullptr && effect->replaces_beta ? 1 : 0;
    Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(r0.size(), p);
    for (int c = first; c < p; ++c) {
      const double h = 0.01;
      std::vector<double> up = u;
      std::vector<double> down = u;
      up[static_cast<std::size_t>(c)] = std::min(1.0, u[static_cast<std::size_t>(c)] + h);
      down[static_cast<std::size_t>(c)] = std::max(0.0, u[static_cast<std::size_t>(c)] - h);
      const std::vector<double> vu = physical(effect, up);
      const std::vector<double> vd = physical(effect, down);
      const double step =
          c == 0 ? up[0] - down[0] : vu[static_cast<std::size_t>(c - 1)] - vd[static_cast<std::size_t>(c - 1)];
      evaluations += 2;
      const Eigen::VectorXd ru = scorer_.fit_residuals(simulator_.simulate(settings(effect, up[0], vu)));
      const Eigen::VectorXd rd = scorer_.fit_residuals(simulator_.simulate(settings(effect, down[0], vd)));
      jacobian.col(c) = std::abs(step) > 0 ? Eigen::VectorXd((ru - rd) / step) : Eigen::VectorXd::Zero(r0.size());
    }
    const int fitted = p - first;
    const double n = static_cast<double>(r0.size());
    const double s2 = n > fitted ? r0.squaredNorm() / (n - fitted) : 0.0;
    const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(normal, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::VectorXd sigma = svd.singularValues();
    Eigen::VectorXd inverse_sigma = Eigen::VectorXd::Zero(sigma.size());
    for (Eigen::Index i = 0; i < sigma.size(); ++i) {
      if (sigma(0) > 0 && sigma(i) > 1e-12 * sigma(0)) inverse_sigma(i) = 1.0 / sigma(i);
    }
    const Eigen::MatrixXd covariance = s2 * svd.matrixV() * inverse_sigma.asDiagonal() * svd.matrixU().transpose();
    auto std_of = [&](int c) {
      const double v = covariance(c, c);
      bool identified = jacobian.col(c).squaredNorm() > 0;
      for (Eigen::Index i = 0; i < sigma.size(); ++i) {
        if (inverse_sigma(i) == 0.0 && std::abs(svd.matrixV()(c, i)) > 0.5) identified = false;
      }
      return identified && v >= 0 ? std::sqrt(v) : std::numeric_limits<double>::infinity();
    };
    f.beta_std = std_of(0);
    for (int c = 1; c < p; ++c) f.std.push_back(std_of(c));
    if (first == 1) {
      // Per-patch stiffness: msm_beta is the bulk's (the larger group of patches by msm_beta).
      f.beta = split_patches(context_.patches, f.values).bulk_beta;
      f.beta_std = std::numeric_limits<double>::infinity();
    }
    f.bic = n > 0 && f.score.fit_rss > 0 ? n * std::log(f.score.fit_rss / n) + fitted * std::log(n) : 0.0;
    return f;
  }

  int evaluations = 0;

 private:
  const RecordingSimulator& simulator_;
  const Scorer& scorer_;
  const EffectContext& context_;
};

std::string id_list(const std::vector<int>& ids) {
  std::ostringstream out;
  for (std::size_t i = 0; i < ids.size();) {
    std::size_t j = i;
    while (j + 1 < ids.size() && ids[j + 1] == ids[j] + 1) ++j;
    if (i > 0) out << ", ";
    out << ids[i];
    if (j > i) out << "-" << ids[j];
    i = j + 1;
    if (i >= 12 && i < ids.size()) {
      out << " and " << ids.size() - i << " more";
      break;
    }
  }
  return out.str();
}

std::string number(double v) {
  std::ostringstream out;
  out.precision(3);
  out << v;
  return out.str();
}

// The region of a per-patch stiffness fit as a sentence.
std::string describe_region(const std::vector<std::vector<int>>& patches, const PatchSplit& split) {
  std::vector<int> ids;
  for (std::size_t k : split.region) ids.insert(ids.end(), patches[k].begin(), patches[k].end());
  std::sort(ids.begin(), ids.end());
  if (ids.empty()) return "";
  return "Particles " + id_list(ids) + " are " + (split.region_beta < split.bulk_beta ? "stiffer" : "softer") +
         " (msm_beta " + number(split.region_beta) + ") than the rest (msm_beta " + number(split.bulk_beta) + ").";
}

std::vector<double> magnitudes(const Recording& recording, const std::vector<double>& simulated) {
  return residual_magnitudes(
      make_residual_field(recording.positions, simulated, recording.particle_count, recording.dimension));
}

}  // namespace

DiagnoseResult diagnose_recording(const Recording& recording, const DiagnoseOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  if (options.model == "fem") return diagnose_recording_fem(recording, options);
  if (options.model != "msm") throw std::runtime_error("model '" + options.model + "' is unknown; use msm or fem");
  const int frames = recording.frame_count();
  const int n = recording.particle_count;
  const int dim = recording.dimension;
  if (frames < kMinFrames) {
    throw std::runtime_error("too few frames (" + std::to_string(frames) + "); diagnose needs at least " +
                             std::to_string(kMinFrames));
  }
  auto report = [&](const std::string& stage, int done, int total) {
    if (options.progress) options.progress(stage, done, total);
  };

  // Held-out blocks of about 0.1 s.
  int block = options.holdout_block_frames;
  if (block <= 0) {
    const double duration = recording.frame_times_s.back() - recording.frame_times_s.front();
    const double rate = duration > 0 ? (frames - 1) / duration : 30.0;
    block = std::max(3, static_cast<int>(std::lround(0.1 * rate)));
  }
  std::vector<unsigned char> pairs = compared_pairs(recording);
  long compared = 0;
  for (unsigned char p : pairs) compared += p;
  if (compared == 0) throw std::runtime_error("no particle is observed while free; nothing to compare the model with");
  Scorer scorer(recording, pairs, interleaved_holdout(frames, block));

  const double noise_std = estimate_noise_std(recording);
  const double noise_rms = noise_std * std::sqrt(static_cast<double>(dim));

  // Does anything move? Largest displacement of an observed particle from its first position.
  double travel = 0;
  for (int k = 0; k < frames; ++k) {
    for (int i = 0; i < n; ++i) {
      if (!recording.observed(k, i) || !recording.observed(0, i)) continue;
      double squared = 0;
      for (int d = 0; d < dim; ++d) {
        const double step = recording.position(k, i, d) - recording.position(0, i, d);
        squared += step * step;
      }
      travel = std::max(travel, std::sqrt(squared));
    }
  }
  if (!(travel > 5.0 * std::max(noise_rms, 1e-12))) {
    throw std::runtime_error("nothing moves beyond the measurement noise; there is no deformation to diagnose");
  }

  report("baseline", 0, 1);
  const RecordingSimulator simulator(recording);
  EffectContext context;
  context.dimension = dim;
  context.particle_count = n;
  {
    const std::vector<double>& rest = simulator.rest();
    double size = 0;
    for (int d = 0; d < dim; ++d) {
      double lo = std::numeric_limits<double>::infinity();
      double hi = -lo;
      for (int i = 0; i < n; ++i) {
        lo = std::min(lo, rest[static_cast<std::size_t>(i * dim + d)]);
        hi = std::max(hi, rest[static_cast<std::size_t>(i * dim + d)]);
      }
      size = std::max(size, hi - lo);
    }
    context.object_size = size > 0 ? size : 1.0;
    double normal_length = 0;
    for (double v : simulator.support_normal()) normal_length += v * v;
    context.has_support = normal_length > 0.5;
  }
  Fitter fitter(simulator, scorer, context);

  // Baseline: msm_beta by a grid and golden section on the fitting frames.
  double best_beta = 0.5;
  double best_rss = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= 10; ++i) {
    const double beta = i / 10.0;
    const double rss = fitter.objective(nullptr, {beta});
    if (rss < best_rss) {
      best_rss = rss;
      best_beta = beta;
    }
  }
  golden([&](double beta) { return fitter.objective(nullptr, {beta}); }, std::max(0.0, best_beta - 0.1),
         std::min(1.0, best_beta + 0.1), 1e-3, best_beta, best_rss);
  const Fit baseline = fitter.finish(nullptr, {best_beta});
  report("baseline", 1, 1);

  DiagnoseResult result;
  Diagnosis& out = result.diagnosis;
  out.recording = recording.name;
  out.noise_rms = noise_rms;
  out.baseline.model = "msm";
  out.baseline.parameters = {{"msm_alpha", 1.0}, {"msm_beta", baseline.beta}};
  out.baseline.parameter_std = {{"msm_beta", baseline.beta_std}};
  out.baseline.rms = baseline.score.held_rms();

  // Locate.
  const ResidualField field = make_residual_field(recording.positions, baseline.simulated, n, dim);
  out.location = locate_mismatch(field, recording.frame_times_s, noise_std);
  context.located = out.location.particles;
  context.patches = spatial_patches(simulator.rest(), dim,
                                    std::max(6, (n - static_cast<int>(recording.fixed.size())) / 8), recording.fixed);
  const std::map<std::string, double> signatures =
      residual_signatures(recording, baseline.simulated, field, out.location, noise_std);

  // Candidates.
  const double misfit = noise_rms > 0 ? out.baseline.rms / noise_rms : std::numeric_limits<double>::infinity();
  const std::vector<Effect> effects = effect_catalogue(context);
  std::vector<Fit> fits;
  for (std::size_t e = 0; e < effects.size(); ++e) {
    report("effects", static_cast<int>(e), static_cast<int>(effects.size()));
    fits.push_back(fitter.fit(&effects[e], baseline.beta));
  }
  report("effects", static_cast<int>(effects.size()), static_cast<int>(effects.size()));

  struct Ranked {
    std::size_t index;
    double significance;
    bool passes;
  };
  std::vector<Ranked> ranked;
  for (std::size_t e = 0; e < effects.size(); ++e) {
    const Fit& f = fits[e];
    double significance = 0;
    for (std::size_t p = 0; p < f.values.size(); ++p) {
      const EffectParameter& parameter = effects[e].parameters[p];
      // A per-patch stiffness is tested against the bulk msm_beta, others against their null.
      const double null_value = effects[e].replaces_beta ? f.beta : parameter.null_value;
      if (std::isfinite(null_value) && std::isfinite(f.std[p]) && f.std[p] > 0) {
        significance = std::max(significance, std::abs(f.values[p] - null_value) / f.std[p]);
      }
    }
    const double improvement = out.baseline.rms > 0 ? 1.0 - f.score.held_rms() / out.baseline.rms : 0.0;
    const bool passes = misfit >= kMinMisfit && improvement >= kMinImprovement && baseline.bic - f.bic >= kMinBicGain &&
                        significance >= kMinSignificance;
    ranked.push_back({e, significance, passes});
  }
  std::sort(ranked.begin(), ranked.end(), [&](const Ranked& a, const Ranked& b) {
    if (a.passes != b.passes) return a.passes;
    return fits[a.index].score.held_rms() < fits[b.index].score.held_rms();
  });
  for (const Ranked& r : ranked) {
    const Fit& f = fits[r.index];
    Candidate c;
    c.effect = effects[r.index].name;
    for (std::size_t p = 0; p < f.values.size(); ++p) {
      c.parameters[effects[r.index].parameters[p].name] = f.values[p];
      c.parameter_std[effects[r.index].parameters[p].name] = f.std[p];
    }
    c.parameters["msm_beta"] = f.beta;
    c.parameter_std["msm_beta"] = f.beta_std;
    c.rms = f.score.held_rms();
    c.bic = f.bic;
    out.candidates.push_back(c);
  }

  const bool found = !ranked.empty() && ranked.front().passes;
  const std::vector<double> baseline_map = magnitudes(recording, baseline.simulated);
  const double t0 = out.location.t_start;
  const double t1 = out.location.t_end;
  std::ostringstream where;
  if (!out.location.particles.empty()) {
    where << "particles " << id_list(out.location.particles) << " between t = " << number(t0) << " s and " << number(t1)
          << " s";
  }
  if (found) {
    const Ranked& best = ranked.front();
    const Effect& effect = effects[best.index];
    const Fit& f = fits[best.index];
    out.verdict = "missing_physics";
    out.effect = effect.name;
    out.augmented.model = "msm";
    out.augmented.parameters = out.candidates.front().parameters;
    out.augmented.parameter_std = out.candidates.front().parameter_std;
    out.augmented.parameters["msm_alpha"] = 1.0;
    out.augmented.rms = f.score.held_rms();
    out.improvement = 1.0 - out.augmented.rms / out.baseline.rms;
    std::ostringstream text;
    text << "The elastic model misses " << (where.str().empty() ? std::string("the motion") : where.str()) << " by "
         << number(out.baseline.rms) << " " << recording.length_unit << " rms (noise " << number(noise_rms) << "); "
         << effect.physics << " explains it, cutting the held-out rms by " << number(100.0 * out.improvement)
         << " % and moving msm_beta from " << number(baseline.beta) << " to " << number(f.beta) << ".";
    if (effect.replaces_beta) text << " " << describe_region(context.patches, split_patches(context.patches, f.values));
    if (ranked.size() > 1 && ranked[1].passes && fits[ranked[1].index].bic - f.bic < 6.0) {
      text << " " << effects[ranked[1].index].name << " fits almost as well; " << effect.experiment << ".";
    }
    out.explanation = text.str();
    result.evidence.simulated_augmented = f.simulated;
  } else {
    out.augmented = out.baseline;
    out.improvement = 0;
    if (misfit >= kUnknownMisfit && !out.location.particles.empty()) {
      out.verdict = "missing_physics";
      out.effect = "unknown";
      out.explanation = "The elastic model misses " + where.str() + " by " + number(out.baseline.rms) + " " +
                        recording.length_unit + " rms, " + number(misfit) +
                        " times the noise, and no catalogued effect explains it clearly.";
    } else {
      out.verdict = "consistent";
      out.effect = "none";
      out.explanation = "The elastic model explains the recording to within " + number(misfit) +
                        " times the measurement noise on held-out frames; no added physics improves it clearly.";
    }
    result.evidence.simulated_augmented = baseline.simulated;
  }

  DiagnosisEvidence& ev = result.evidence;
  ev.dimension = dim;
  ev.particle_count = n;
  ev.length_unit = recording.length_unit;
  ev.frame_times_s = recording.frame_times_s;
  ev.held_out = scorer.held_out();
  ev.observed = recording.positions;
  ev.simulated_baseline = baseline.simulated;
  ev.residual_baseline = baseline_map;
  ev.residual_augmented = magnitudes(recording, ev.simulated_augmented);
  ev.fixed = recording.fixed;
  for (const DrivenWindow& w : recording.driven) ev.driven.push_back(w.id);
  std::sort(ev.driven.begin(), ev.driven.end());
  ev.driven.erase(std::unique(ev.driven.begin(), ev.driven.end()), ev.driven.end());
  ev.signatures = signatures;
  ev.signatures["misfit_over_noise"] = misfit;
  ev.signatures["simulations"] = fitter.evaluations;
  result.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

nlohmann::json diagnosis_json(const Diagnosis& d) {
  // rms NaN (no position compared, FEM on force-only recordings) is written as null; the FEM's
  // force_rms and force_noise_rms only when they exist.
  auto model = [](const FittedModel& m) {
    nlohmann::json j{{"model", m.model}, {"parameters", m.parameters}, {"rms", nullptr}};
    if (std::isfinite(m.rms)) j["rms"] = m.rms;
    if (std::isfinite(m.force_rms)) j["force_rms"] = m.force_rms;
    return j;
  };
  nlohmann::json candidates = nlohmann::json::array();
  for (const Candidate& c : d.candidates) {
    nlohmann::json j{{"effect", c.effect}, {"rms", nullptr}, {"bic", c.bic}, {"parameters", c.parameters}};
    if (std::isfinite(c.rms)) j["rms"] = c.rms;
    if (std::isfinite(c.force_rms)) j["force_rms"] = c.force_rms;
    candidates.push_back(j);
  }
  nlohmann::json document = {
      {"format", "pliant-diagnosis"},
      {"version", 1},
      {"recording", d.recording},
      {"baseline", model(d.baseline)},
      {"noise_rms", d.noise_rms},
      {"verdict", d.verdict},
      {"effect", d.effect},
      {"explanation", d.explanation},
      {"location", {{"particles", d.location.particles}, {"t_start", d.location.t_start}, {"t_end", d.location.t_end}}},
      {"augmented", model(d.augmented)},
      {"improvement", d.improvement},
      {"candidates", candidates}};
  if (!std::isfinite(d.noise_rms)) document["noise_rms"] = nullptr;
  if (std::isfinite(d.force_noise_rms)) document["force_noise_rms"] = d.force_noise_rms;
  return document;
}

std::string diagnosis_summary(const Diagnosis& d, const std::string& length_unit) {
  std::ostringstream out;
  out << d.recording << ": " << d.verdict;
  if (d.effect != "none") out << " (" << d.effect << ")";
  if (d.baseline.model == "fem") {
    const auto youngs = d.baseline.parameters.find("youngs_modulus");
    out << "\n  baseline fem, E " << number(youngs != d.baseline.parameters.end() ? youngs->second : 0.0) << " Pa";
    if (std::isfinite(d.baseline.force_rms)) {
      out << ", held-out force rms " << number(d.baseline.force_rms) << " N (noise " << number(d.force_noise_rms)
          << " N)";
    }
    if (std::isfinite(d.baseline.rms)) {
      out << ", held-out rms " << number(d.baseline.rms) << " " << length_unit << " (noise " << number(d.noise_rms)
          << " " << length_unit << ")";
    }
    out << "\n";
    if (d.verdict == "missing_physics" && d.effect != "unknown") {
      out << "  with " << d.effect << ":";
      const auto augmented_youngs = d.augmented.parameters.find("youngs_modulus");
      if (augmented_youngs != d.augmented.parameters.end()) out << " E " << number(augmented_youngs->second) << " Pa,";
      if (std::isfinite(d.augmented.force_rms)) out << " held-out force rms " << number(d.augmented.force_rms) << " N,";
      if (std::isfinite(d.augmented.rms))
        out << " held-out rms " << number(d.augmented.rms) << " " << length_unit << ",";
      out << " improvement " << number(100.0 * d.improvement) << " %\n";
    }
    out << "  " << d.explanation << "\n";
    return out.str();
  }
  out << "\n  baseline msm_beta " << number(d.baseline.parameters.at("msm_beta")) << ", held-out rms "
      << number(d.baseline.rms) << " " << length_unit << ", noise " << number(d.noise_rms) << " " << length_unit
      << "\n";
  if (d.verdict == "missing_physics" && d.effect != "unknown") {
    out << "  with " << d.effect << ": held-out rms " << number(d.augmented.rms) << " " << length_unit
        << " (improvement " << number(100.0 * d.improvement) << " %)\n";
  }
  out << "  " << d.explanation << "\n";
  return out.str();
}

}  // namespace pliant::host
