#include "pliant/host/diagnose/diagnose.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>

#include "pliant/host/diagnose/effects.hpp"
#include "pliant/host/diagnose/fem_diagnose.hpp"
#include "pliant/host/diagnose/holdout.hpp"
#include "pliant/host/diagnose/locate.hpp"
#include "pliant/host/diagnose/model_run.hpp"
#include "pliant/host/diagnose/noise_floor.hpp"
#include "pliant/host/diagnose/residual_field.hpp"
#include "pliant/host/diagnose/selection.hpp"
#include "pliant/host/estimate.hpp"
#include "pliant/host/least_squares_fit.hpp"
#include "pliant/host/parallel_fits.hpp"
#include "pliant/host/diagnose/engine.hpp"
#include "words.hpp"

namespace pliant::host {
namespace {

using words::id_list;
using words::number;

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
    for_each_pair(simulated, [&](int frame, double squared) {
      if (held_out_[static_cast<std::size_t>(frame)] != 0) {
        s.held_rss += squared;
        ++s.held_pairs;
      } else {
        s.fit_rss += squared;
        ++s.fit_pairs;
      }
    });
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

  /// The number of scalars fit_residuals returns.
  int fit_residual_count() const {
    long pairs = 0;
    for (int k = 0; k < recording_.frame_count(); ++k) {
      if (held_out_[static_cast<std::size_t>(k)] != 0) continue;
      for (int i = 0; i < recording_.particle_count; ++i) {
        pairs += pairs_[static_cast<std::size_t>(k) * static_cast<std::size_t>(recording_.particle_count) +
                        static_cast<std::size_t>(i)];
      }
    }
    return static_cast<int>(pairs * recording_.dimension);
  }

  /// The particle of every scalar fit_residuals returns, in the same order.
  std::vector<int> fit_residual_particles() const {
    std::vector<int> ids;
    const int n = recording_.particle_count;
    for (int k = 0; k < recording_.frame_count(); ++k) {
      if (held_out_[static_cast<std::size_t>(k)] != 0) continue;
      for (int i = 0; i < n; ++i) {
        if (pairs_[static_cast<std::size_t>(k) * static_cast<std::size_t>(n) + static_cast<std::size_t>(i)] == 0)
          continue;
        ids.insert(ids.end(), static_cast<std::size_t>(recording_.dimension), i);
      }
    }
    return ids;
  }

  /// Held-out residual sum of squares and compared pairs per held-out block (a run of
  /// consecutive held-out frames), in frame order: what a block bootstrap of frames resamples.
  std::vector<Score> held_blocks(const std::vector<double>& simulated) const {
    int block_count = 0;
    const std::vector<int> block_of = held_block_of_frame(held_out_, block_count);
    std::vector<Score> blocks(static_cast<std::size_t>(block_count));
    for_each_pair(simulated, [&](int frame, double squared) {
      const int block = block_of[static_cast<std::size_t>(frame)];
      if (block < 0) return;
      blocks[static_cast<std::size_t>(block)].held_rss += squared;
      ++blocks[static_cast<std::size_t>(block)].held_pairs;
    });
    return blocks;
  }

  const std::vector<unsigned char>& held_out() const { return held_out_; }

 private:
  // Calls visit(frame, squared Euclidean residual) for every compared pair with a finite one.
  template <typename Visit>
  void for_each_pair(const std::vector<double>& simulated, Visit&& visit) const {
    const int n = recording_.particle_count;
    const int dim = recording_.dimension;
    for (int k = 0; k < recording_.frame_count(); ++k) {
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
        if (std::isfinite(squared)) visit(k, squared);
      }
    }
  }

  const Recording& recording_;
  std::vector<unsigned char> pairs_;
  std::vector<unsigned char> held_out_;
};

// The parts of the baseline's model form that are not physics: chosen once (estimate's
// selection) and kept for every candidate. msm_alpha is then either held or refitted with each.
struct ModelForm {
  int steps_per_frame = 1;
  bool fit_alpha = false;
  double alpha = 1.0;  // held value, or the baseline's fitted one (the start of every fit)
  double cluster_radius_factor = MsmSetupOptions{}.clusters.radius_factor;
};

struct Fit {
  ModelForm form;              // the model form the fit was made in
  std::vector<double> u;       // search coordinates: msm_beta, msm_alpha when fitted, then the effect's
  std::vector<double> values;  // physical effect parameter values
  std::vector<double> std;     // one std per effect parameter (inf when not identifiable)
  double beta = 0;
  double beta_std = 0;
  double alpha = 1;
  double alpha_std = std::numeric_limits<double>::infinity();  // inf when held
  Score score;
  std::vector<double> simulated;
  Eigen::VectorXd fit_residuals;  // fitting-frame residual scalars, Scorer::fit_residuals order
  int fitted = 0;                 // coordinates fitted
};

// msm_alpha's search coordinate: [0, 1] onto the range the estimator searches.
constexpr double kAlphaLow = 0.05;
double alpha_of(double u) { return kAlphaLow + (1.0 - kAlphaLow) * std::clamp(u, 0.0, 1.0); }
double alpha_coordinate(double alpha) { return std::clamp((alpha - kAlphaLow) / (1.0 - kAlphaLow), 0.0, 1.0); }

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
  Fitter(const RecordingSimulator& simulator, const Scorer& scorer, const EffectContext& context, ModelForm form)
      : simulator_(simulator), scorer_(scorer), context_(context), form_(form) {}

  const ModelForm& form() const { return form_; }

  // Index of the effect's first coordinate in u: after msm_beta and, when fitted, msm_alpha.
  std::size_t effect_offset() const { return form_.fit_alpha ? 2 : 1; }

  // Search coordinates of the baseline at msm_beta `beta` and msm_alpha `alpha`.
  std::vector<double> baseline_coordinates(double beta, double alpha) const {
    std::vector<double> u{beta};
    if (form_.fit_alpha) u.push_back(alpha_coordinate(alpha));
    return u;
  }

  double alpha(const std::vector<double>& u) const { return form_.fit_alpha ? alpha_of(u[1]) : form_.alpha; }

  std::vector<double> physical(const Effect* effect, const std::vector<double>& u) const {
    std::vector<double> values;
    if (effect == nullptr) return values;
    for (std::size_t p = 0; p < effect->parameters.size(); ++p)
      values.push_back(effect->parameters[p].value(u[effect_offset() + p]));
    return values;
  }

  ModelSettings settings(const Effect* effect, const std::vector<double>& u) const {
    ModelSettings s;
    s.msm_beta = std::clamp(u[0], 0.0, 1.0);
    s.msm_alpha = alpha(u);
    s.steps_per_frame = form_.steps_per_frame;
    if (effect != nullptr) effect->apply(physical(effect, u), context_, s);
    return s;
  }

  std::vector<double> simulate(const Effect* effect, const std::vector<double>& u) {
    ++evaluations;
    return simulator_.simulate(settings(effect, u));
  }

  double objective(const Effect* effect, const std::vector<double>& u) {
    return scorer_.score(simulate(effect, u)).fit_rss;
  }

  // Fitting-frame residuals at search coordinates u (one simulation).
  Eigen::VectorXd residuals(const Effect* effect, const std::vector<double>& u) {
    return scorer_.fit_residuals(simulate(effect, u));
  }

  // Coordinates a fit moves: msm_beta unless the effect sets it per patch, msm_alpha when the
  // model form fits it, and every effect parameter.
  std::vector<int> free_coordinates(const Effect* effect, std::size_t size) const {
    std::vector<int> free;
    if (effect == nullptr || !effect->replaces_beta) free.push_back(0);
    for (std::size_t c = 1; c < size; ++c) free.push_back(static_cast<int>(c));
    return free;
  }

  // The baseline: msm_beta by a grid and golden section at the form's msm_alpha, then, when the
  // form fits msm_alpha, both together by Levenberg-Marquardt.
  Fit fit_baseline() {
    const std::vector<double> start = baseline_coordinates(0.5, form_.alpha);
    auto at_beta = [&](double beta) {
      std::vector<double> u = start;
      u[0] = beta;
      return objective(nullptr, u);
    };
    double best_beta = 0.5;
    double best_rss = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 10; ++i) {
      const double rss = at_beta(i / 10.0);
      if (rss < best_rss) {
        best_rss = rss;
        best_beta = i / 10.0;
      }
    }
    golden(at_beta, std::max(0.0, best_beta - 0.1), std::min(1.0, best_beta + 0.1), 1e-3, best_beta, best_rss);
    std::vector<double> u = start;
    u[0] = best_beta;
    if (form_.fit_alpha) levenberg_marquardt(nullptr, u);
    return finish(nullptr, u);
  }

  // An effect's fit: a grid over its scanned coordinates (responses flat near the null need
  // it), msm_beta profiled out at every grid point by Gauss-Newton (it trades off against
  // most effects), then bounded Levenberg-Marquardt on every free coordinate from the two best
  // grid points. `baseline` gives the start of msm_beta and msm_alpha.
  Fit fit(const Effect* effect, const Fit& baseline) {
    std::vector<double> start(baseline.u.begin(), baseline.u.begin() + static_cast<long>(effect_offset()));
    std::vector<std::size_t> scanned;
    for (std::size_t p = 0; p < effect->parameters.size(); ++p) {
      const EffectParameter& parameter = effect->parameters[p];
      double u = 0.0;
      if (std::isfinite(parameter.null_value))
        u = parameter.coordinate(parameter.null_value);
      else if (effect->replaces_beta)
        u = parameter.coordinate(baseline.beta);
      start.push_back(u);
      if (parameter.scanned) scanned.push_back(effect_offset() + p);
    }

    struct Seed {
      std::vector<double> u;
      double cost;
    };
    std::vector<Seed> seeds;
    const int per_axis = scanned.size() <= 1 ? 7 : (scanned.size() == 2 ? 5 : 4);
    long points = 1;
    for (std::size_t a = 0; a < scanned.size(); ++a) points *= per_axis;
    // With msm_alpha fitted, the grid also starts from msm_alpha = 1: the baseline's msm_alpha
    // may have absorbed part of the effect (a lagging model mimics creep), and from there the
    // effect's own basin can be out of reach.
    std::vector<double> alpha_starts;
    if (form_.fit_alpha) {
      alpha_starts.push_back(start[1]);
      if (start[1] < alpha_coordinate(0.95)) alpha_starts.push_back(1.0);
    }
    for (std::size_t a = 0; a < std::max<std::size_t>(alpha_starts.size(), 1); ++a) {
      if (form_.fit_alpha) start[1] = alpha_starts[a];
      for (long index = 0; index < points; ++index) {
        std::vector<double> u = start;
        long rest = index;
        for (std::size_t c : scanned) {
          u[c] = static_cast<double>(rest % per_axis) / (per_axis - 1);
          rest /= per_axis;
        }
        const double cost = effect->replaces_beta ? residuals(effect, u).squaredNorm() : profile_beta(effect, u);
        seeds.push_back({u, cost});
      }
    }
    std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.cost < b.cost; });
    std::vector<double> best_u = seeds.front().u;
    double best_cost = std::numeric_limits<double>::infinity();
    const std::size_t starts = std::min<std::size_t>(seeds.size(), 2);
    for (std::size_t k = 0; k < starts; ++k) {
      std::vector<double> u = seeds[k].u;
      const double cost = levenberg_marquardt(effect, u);
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

  // Bounded Levenberg-Marquardt (fit_least_squares) on the free coordinates, in the unit search
  // box: forward differences (every evaluation is a simulation), plain least squares, stopped
  // when a step gains less than 1e-5 of the cost. The uncertainty is finish()'s. Returns the
  // fitting-frame residual sum of squares at the final u (u unchanged, and the sum at u, when
  // the model cannot be evaluated there).
  double levenberg_marquardt(const Effect* effect, std::vector<double>& u) {
    const std::vector<int> coordinates = free_coordinates(effect, u.size());
    std::vector<FitParameter> parameters;
    for (int c : coordinates) {
      parameters.push_back(
          {coordinate_name(effect, c), std::clamp(u[static_cast<std::size_t>(c)], 0.0, 1.0), 0.0, 1.0, false});
    }
    const ResidualFunction function = [&](const std::vector<double>& values, std::vector<double>& out) {
      std::vector<double> trial = u;
      for (std::size_t k = 0; k < coordinates.size(); ++k) trial[static_cast<std::size_t>(coordinates[k])] = values[k];
      const Eigen::VectorXd r = residuals(effect, trial);
      if (r.size() != static_cast<Eigen::Index>(out.size())) return false;
      std::copy(r.data(), r.data() + r.size(), out.begin());
      return true;
    };
    FitOptions options;
    options.loss = RobustLoss::none;
    options.central_differences = false;
    options.difference_step = 0.005;
    options.max_iterations = 25;
    options.function_tolerance = 1e-5;
    options.parameter_tolerance = 1e-6;
    options.initial_damping = 1e-2;
    options.projected_line_search = false;
    options.uncertainty = false;
    try {
      const FitResult result = fit_least_squares(parameters, scorer_.fit_residual_count(), function, options);
      for (std::size_t k = 0; k < coordinates.size(); ++k)
        u[static_cast<std::size_t>(coordinates[k])] = result.values[k];
      return 2.0 * result.final_cost;
    } catch (const std::exception&) {
      return residuals(effect, u).squaredNorm();
    }
  }

  // The fit at u with its scores and the std of every fitted parameter.
  Fit finish(const Effect* effect, const std::vector<double>& u) {
    Fit f;
    f.form = form_;
    f.u = u;
    f.beta = u[0];
    f.alpha = alpha(u);
    f.values = physical(effect, u);
    f.simulated = simulate(effect, u);
    f.score = scorer_.score(f.simulated);
    f.fit_residuals = scorer_.fit_residuals(f.simulated);
    // Uncertainty: J = d residual / d parameter by central differences; cov = s^2 (J^T J)^-1,
    // before the design effect (rank_fits widens it).
    const std::vector<int> coordinates = free_coordinates(effect, u.size());
    const Eigen::VectorXd& r0 = f.fit_residuals;
    const int p = static_cast<int>(u.size());
    Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(r0.size(), p);
    for (int c : coordinates) {
      const double h = 0.01;
      std::vector<double> up = u;
      std::vector<double> down = u;
      up[static_cast<std::size_t>(c)] = std::min(1.0, u[static_cast<std::size_t>(c)] + h);
      down[static_cast<std::size_t>(c)] = std::max(0.0, u[static_cast<std::size_t>(c)] - h);
      const double step = physical_value(effect, up, c) - physical_value(effect, down, c);
      const Eigen::VectorXd ru = residuals(effect, up);
      const Eigen::VectorXd rd = residuals(effect, down);
      jacobian.col(c) = std::abs(step) > 0 ? Eigen::VectorXd((ru - rd) / step) : Eigen::VectorXd::Zero(r0.size());
    }
    f.fitted = static_cast<int>(coordinates.size());
    const double n = static_cast<double>(r0.size());
    const double s2 = n > f.fitted ? r0.squaredNorm() / (n - f.fitted) : 0.0;
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
    if (form_.fit_alpha) f.alpha_std = std_of(1);
    for (int c = static_cast<int>(effect_offset()); c < p; ++c) f.std.push_back(std_of(c));
    if (effect != nullptr && effect->replaces_beta) {
      // Per-patch stiffness: msm_beta is the bulk's (the larger group of patches by msm_beta).
      f.beta = split_patches(context_.patches, f.values).bulk_beta;
      f.beta_std = std::numeric_limits<double>::infinity();
    }
    return f;
  }

  int evaluations = 0;

 private:
  // Coordinate c's name: msm_beta, msm_alpha, or the effect parameter's.
  std::string coordinate_name(const Effect* effect, int c) const {
    if (c == 0) return "msm_beta";
    if (form_.fit_alpha && c == 1) return "msm_alpha";
    return effect->parameters[static_cast<std::size_t>(c) - effect_offset()].name;
  }

  // Coordinate c of u in physical units: msm_beta, msm_alpha, or the effect parameter.
  double physical_value(const Effect* effect, const std::vector<double>& u, int c) const {
    if (c == 0) return u[0];
    if (form_.fit_alpha && c == 1) return alpha(u);
    return effect->parameters[static_cast<std::size_t>(c) - effect_offset()].value(u[static_cast<std::size_t>(c)]);
  }

  const RecordingSimulator& simulator_;
  const Scorer& scorer_;
  const EffectContext& context_;
  ModelForm form_;
};

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

// The model form of the baseline a user would fit: estimate's selection of msm_alpha (held or
// fitted) and of the steps per frame (docs/estimation.md), made on the whole recording. Both
// held by the options: no selection.
struct FormChoice {
  ModelForm form;
  std::string reason;
};

FormChoice choose_model_form(const Recording& recording, const DiagnoseOptions& options) {
  FormChoice choice;
  if (options.alpha == AlphaMode::fixed && options.steps_per_frame > 0 && !options.cluster_radius_auto) {
    choice.form.steps_per_frame = options.steps_per_frame;
    choice.form.alpha = options.msm_alpha;
    choice.form.cluster_radius_factor = options.cluster_radius_factor;
    choice.reason = "msm_alpha, the steps per frame and the cluster radius were held as asked.";
    return choice;
  }
  EstimateOptions estimate;
  estimate.alpha = options.alpha;
  estimate.msm_alpha = options.msm_alpha;
  estimate.steps_per_frame = options.steps_per_frame;
  estimate.cluster_radius_auto = options.cluster_radius_auto;
  estimate.setup.clusters.radius_factor = options.cluster_radius_factor;
  estimate.input_noise_samples = 0;
  const BaselineChoice selection = estimate_recording(recording, estimate).baseline;
  choice.form.steps_per_frame = selection.steps_per_frame();
  choice.form.fit_alpha = selection.alpha_fitted();
  choice.form.alpha = selection.candidates.empty()
                          ? options.msm_alpha
                          : selection.candidates[static_cast<std::size_t>(selection.chosen)].msm_alpha;
  choice.form.cluster_radius_factor = selection.cluster_radius_factor(estimate.setup.clusters.radius_factor);
  choice.reason = selection.reason;
  return choice;
}

// A fit as selection sees it (selection.hpp): msm_beta and msm_alpha are nuisance coordinates;
// an effect's parameters are tested against their nulls, a per-patch stiffness against the
// bulk's msm_beta.
FitEvidence evidence_of(const Scorer& scorer, const Fit& fit, const Effect* effect) {
  FitEvidence evidence;
  evidence.fit_residuals = fit.fit_residuals;
  evidence.fitted = fit.fitted;
  for (const Score& block : scorer.held_blocks(fit.simulated)) {
    evidence.held_blocks.push_back({block.held_rss, block.held_pairs});
  }
  evidence.values = fit.values;
  evidence.std = fit.std;
  for (std::size_t p = 0; effect != nullptr && p < effect->parameters.size(); ++p) {
    evidence.nulls.push_back(effect->replaces_beta ? fit.beta : effect->parameters[p].null_value);
  }
  return evidence;
}

// Largest displacement of an observed particle from its first observed position.
double largest_travel(const Recording& recording) {
  double travel = 0;
  for (int k = 0; k < recording.frame_count(); ++k) {
    for (int i = 0; i < recording.particle_count; ++i) {
      if (!recording.observed(k, i) || !recording.observed(0, i)) continue;
      double squared = 0;
      for (int d = 0; d < recording.dimension; ++d) {
        const double step = recording.position(k, i, d) - recording.position(0, i, d);
        squared += step * step;
      }
      travel = std::max(travel, std::sqrt(squared));
    }
  }
  return travel;
}

// Size of the object (largest extent of the rest shape over the axes) and whether it stands on
// a support line or plane.
void describe_object(const RecordingSimulator& simulator, int n, int dim, EffectContext& context) {
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

// The MSM model as diagnosis-v1 writes it: msm_beta, msm_alpha (with its std when fitted) and
// the model form.
FittedModel msm_model(const Fit& fit, const ModelForm& form, const std::string& reason) {
  FittedModel model;
  model.model = "msm";
  model.parameters = {{"msm_alpha", fit.alpha}, {"msm_beta", fit.beta}};
  model.parameter_std = {{"msm_beta", fit.beta_std}};
  if (form.fit_alpha) model.parameter_std["msm_alpha"] = fit.alpha_std;
  model.rms = fit.score.held_rms();
  model.steps_per_frame = form.steps_per_frame;
  model.cluster_radius_factor = form.cluster_radius_factor;
  model.alpha_fitted = form.fit_alpha;
  model.form_reason = reason;
  return model;
}

// The MSM as a diagnosis model (engine.hpp).
class MsmDiagnosis final : public DiagnosisModel {
 public:
  MsmDiagnosis(const Recording& recording, const DiagnoseOptions& options)
      : recording_(recording), options_(options), scorer_(make_scorer(recording, options)) {
    noise_std_ = estimate_noise_std(recording);
    noise_rms_ = noise_std_ * std::sqrt(static_cast<double>(recording.dimension));
    if (!(largest_travel(recording) > 5.0 * std::max(noise_rms_, 1e-12))) {
      throw std::runtime_error("nothing moves beyond the measurement noise; there is no deformation to diagnose");
    }
  }

  // The baseline a user would fit: estimate's model form (msm_alpha, steps, radius), then
  // msm_beta (and msm_alpha when fitted) on the fitting frames.
  void fit_baseline(Diagnosis& out) override {
    form_ = choose_model_form(recording_, options_);
    setup_.clusters.radius_factor = form_.form.cluster_radius_factor;
    simulator_ = std::make_unique<RecordingSimulator>(recording_, setup_);
    context_.dimension = recording_.dimension;
    context_.particle_count = recording_.particle_count;
    describe_object(*simulator_, recording_.particle_count, recording_.dimension, context_);
    Fitter fitter(*simulator_, scorer_, context_, form_.form);
    baseline_ = fitter.fit_baseline();
    simulations_ += fitter.evaluations;
    out.noise_rms = noise_rms_;
    out.baseline = msm_model(baseline_, form_.form, form_.reason);
  }

  std::map<std::string, double> locate(Diagnosis& out) override {
    const int n = recording_.particle_count;
    const int dim = recording_.dimension;
    const ResidualField field = make_residual_field(recording_.positions, baseline_.simulated, n, dim);
    out.location = locate_mismatch(field, recording_.frame_times_s, noise_std_);
    location_ = out.location;
    context_.located = out.location.particles;
    context_.patches = spatial_patches(
        simulator_->rest(), dim, std::max(6, (n - static_cast<int>(recording_.fixed.size())) / 8), recording_.fixed);
    return residual_signatures(recording_, baseline_.simulated, field, out.location, noise_std_);
  }

  std::vector<std::string> catalogue() override {
    effects_ = effect_catalogue(context_);
    std::vector<std::string> names;
    for (const Effect& e : effects_) names.push_back(e.name);
    return names;
  }

  // Every effect is fitted independently: on worker threads, each with its own simulators (a
  // simulator holds its run state). The result does not depend on the thread count. When the
  // baseline's form moved away from the plain one (msm_alpha 1, one step per frame, the
  // setup's radius), every effect is also fitted in the plain form and the better fit kept:
  // msm_alpha, steps or radius chosen without the effect may have absorbed part of it.
  void fit_effects(int threads, const std::function<void()>& one_done) override {
    ModelForm plain;
    plain.cluster_radius_factor = options_.cluster_radius_factor;
    const bool refit_plain = options_.alpha == AlphaMode::automatic && options_.steps_per_frame == 0 &&
                             options_.cluster_radius_auto &&
                             (form_.form.fit_alpha || form_.form.steps_per_frame != 1 ||
                              form_.form.cluster_radius_factor != plain.cluster_radius_factor);
    MsmSetupOptions plain_setup;
    plain_setup.clusters.radius_factor = plain.cluster_radius_factor;
    std::unique_ptr<RecordingSimulator> plain_simulator;
    Fit plain_baseline;
    if (refit_plain) {
      plain_simulator = std::make_unique<RecordingSimulator>(recording_, plain_setup);
      Fitter plain_fitter(*plain_simulator, scorer_, context_, plain);
      plain_baseline = plain_fitter.fit_baseline();
      simulations_ += plain_fitter.evaluations;
    }
    struct Worker {
      std::unique_ptr<RecordingSimulator> simulator;  // null: the caller's
      std::unique_ptr<RecordingSimulator> plain_simulator;
    };
    fits_.assign(effects_.size(), Fit{});
    std::vector<int> evaluations(effects_.size(), 0);
    run_on_workers(
        effects_.size(), worker_count(effects_.size(), threads),
        [&](bool is_caller) {
          Worker worker;
          if (!is_caller) worker.simulator = std::make_unique<RecordingSimulator>(recording_, setup_);
          if (refit_plain) {
            worker.plain_simulator =
                is_caller ? std::move(plain_simulator) : std::make_unique<RecordingSimulator>(recording_, plain_setup);
          }
          return worker;
        },
        [&](Worker& worker, std::size_t e) {
          Fitter own(worker.simulator ? *worker.simulator : *simulator_, scorer_, context_, form_.form);
          fits_[e] = own.fit(&effects_[e], baseline_);
          evaluations[e] = own.evaluations;
          if (!refit_plain) return;
          Fitter in_plain(*worker.plain_simulator, scorer_, context_, plain);
          Fit in_plain_form = in_plain.fit(&effects_[e], plain_baseline);
          evaluations[e] += in_plain.evaluations;
          if (in_plain_form.fit_residuals.squaredNorm() < fits_[e].fit_residuals.squaredNorm()) {
            fits_[e] = std::move(in_plain_form);
          }
        },
        one_done);
    for (int count : evaluations) simulations_ += count;
  }

  FitEvidence baseline_evidence() const override { return evidence_of(scorer_, baseline_, nullptr); }
  FitEvidence effect_evidence(std::size_t e) const override { return evidence_of(scorer_, fits_[e], &effects_[e]); }
  double noise_misfit() const override { return noise_rms_; }

  // Residuals cluster by particle and axis.
  std::vector<int> residual_clusters() const override {
    const int dim = recording_.dimension;
    std::vector<int> clusters = scorer_.fit_residual_particles();
    for (std::size_t j = 0; j < clusters.size(); ++j) {
      clusters[j] = clusters[j] * dim + static_cast<int>(j % static_cast<std::size_t>(dim));
    }
    return clusters;
  }

  Candidate candidate(std::size_t e, const RankedEffect& ranked, double deff) const override {
    const Fit& f = fits_[e];
    Candidate c;
    c.effect = effects_[e].name;
    for (std::size_t p = 0; p < f.values.size(); ++p) {
      c.parameters[effects_[e].parameters[p].name] = f.values[p];
      c.parameter_std[effects_[e].parameters[p].name] = f.std[p] * std::sqrt(deff);
    }
    c.parameters["msm_beta"] = f.beta;
    c.parameter_std["msm_beta"] = f.beta_std * std::sqrt(deff);
    if (f.form.fit_alpha) {
      c.parameters["msm_alpha"] = f.alpha;
      c.parameter_std["msm_alpha"] = f.alpha_std * std::sqrt(deff);
    }
    c.rms = f.score.held_rms();
    c.bic = ranked.bic;
    c.explained = ranked.explained;
    return c;
  }

  void explain_named(std::size_t e, Diagnosis& out) const override {
    const Effect& effect = effects_[e];
    const Fit& f = fits_[e];
    const bool same_form = f.form.steps_per_frame == form_.form.steps_per_frame &&
                           f.form.fit_alpha == form_.form.fit_alpha &&
                           f.form.cluster_radius_factor == form_.form.cluster_radius_factor;
    out.augmented =
        msm_model(f, f.form, same_form ? form_.reason : "the plain form fitted the effect better than the baseline's");
    for (const auto& [name, value] : out.candidates.front().parameters) out.augmented.parameters[name] = value;
    out.augmented.parameter_std = out.candidates.front().parameter_std;
    out.improvement = 1.0 - out.augmented.rms / out.baseline.rms;
    const std::string where = where_words();
    std::ostringstream text;
    text << "The elastic model misses " << (where.empty() ? std::string("the motion") : where) << " by "
         << number(out.baseline.rms) << " " << recording_.length_unit << " rms (noise " << number(noise_rms_) << "); "
         << effect.physics << " explains it, cutting the held-out rms by " << number(100.0 * out.improvement)
         << " % and moving msm_beta from " << number(baseline_.beta) << " to " << number(f.beta) << ".";
    if (effect.replaces_beta)
      text << " " << describe_region(context_.patches, split_patches(context_.patches, f.values));
    if (!out.runner_up.empty()) text << " " << out.runner_up << " fits almost as well; " << effect.experiment << ".";
    out.explanation = text.str();
  }

  UnexplainedWords unexplained_words(const Diagnosis& out) const override {
    UnexplainedWords w;
    w.model = "The elastic model";
    w.where = where_words();
    w.size = number(out.baseline.rms) + " " + recording_.length_unit + " rms";
    w.misfit_word = "rms";
    return w;
  }

  void fill_evidence(bool named, std::size_t e, DiagnosisEvidence& evidence) const override {
    fill_recording_evidence(recording_, scorer_.held_out(), evidence);
    evidence.simulated_baseline = baseline_.simulated;
    evidence.simulated_augmented = named ? fits_[e].simulated : baseline_.simulated;
    evidence.residual_baseline = magnitudes(recording_, evidence.simulated_baseline);
    evidence.residual_augmented = magnitudes(recording_, evidence.simulated_augmented);
  }

  int simulations() const override { return simulations_; }

 private:
  // Held-out blocks of about 0.1 s; every free, observed particle is compared.
  static Scorer make_scorer(const Recording& recording, const DiagnoseOptions& options) {
    const int block = holdout_block_frames(recording, options.holdout_block_frames, 1);
    std::vector<unsigned char> pairs = compared_pairs(recording);
    if (std::find(pairs.begin(), pairs.end(), 1) == pairs.end()) {
      throw std::runtime_error("no particle is observed while free; nothing to compare the model with");
    }
    return Scorer(recording, std::move(pairs), interleaved_holdout(recording.frame_count(), block));
  }

  std::string where_words() const {
    if (location_.particles.empty()) return "";
    std::ostringstream where;
    where << "particles " << id_list(location_.particles) << " between t = " << number(location_.t_start) << " s and "
          << number(location_.t_end) << " s";
    return where.str();
  }

  const Recording& recording_;
  const DiagnoseOptions& options_;
  Scorer scorer_;
  double noise_std_ = 0;
  double noise_rms_ = 0;
  FormChoice form_;
  MsmSetupOptions setup_;
  std::unique_ptr<RecordingSimulator> simulator_;
  EffectContext context_;
  Fit baseline_;
  Location location_;
  std::vector<Effect> effects_;
  std::vector<Fit> fits_;
  int simulations_ = 0;
};

}  // namespace

DiagnoseResult diagnose_recording(const Recording& recording, const DiagnoseOptions& options) {
  if (options.model == "fem") return diagnose_recording_fem(recording, options);
  if (options.model != "msm") throw std::runtime_error("model '" + options.model + "' is unknown; use msm or fem");
  require_enough_frames(recording);
  MsmDiagnosis model(recording, options);
  return run_diagnosis(model, recording.name, options);
}

nlohmann::json diagnosis_json(const Diagnosis& d) {
  // rms NaN (no position compared, FEM on force-only recordings) is written as null; the FEM's
  // force_rms and force_noise_rms only when they exist.
  auto model = [](const FittedModel& m) {
    nlohmann::json j{{"model", m.model}, {"parameters", m.parameters}, {"rms", nullptr}};
    if (std::isfinite(m.rms)) j["rms"] = m.rms;
    if (std::isfinite(m.force_rms)) j["force_rms"] = m.force_rms;
    if (m.steps_per_frame > 0) {
      j["form"] = {{"steps_per_frame", m.steps_per_frame},
                   {"msm_alpha", m.alpha_fitted ? "fitted" : "held"},
                   {"cluster_radius_factor", m.cluster_radius_factor},
                   {"reason", m.form_reason}};
    }
    return j;
  };
  nlohmann::json candidates = nlohmann::json::array();
  for (const Candidate& c : d.candidates) {
    nlohmann::json j{{"effect", c.effect}, {"rms", nullptr}, {"bic", c.bic}, {"parameters", c.parameters}};
    if (std::isfinite(c.explained)) j["explained"] = c.explained;
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
  if (std::isfinite(d.selection_stability) || !d.runner_up.empty()) {
    nlohmann::json selection = nlohmann::json::object();
    if (std::isfinite(d.selection_stability)) selection["stability"] = d.selection_stability;
    selection["runner_up"] = d.runner_up.empty() ? nlohmann::json() : nlohmann::json(d.runner_up);
    document["selection"] = selection;
  }
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
  out << "\n  baseline msm_beta " << number(d.baseline.parameters.at("msm_beta")) << ", msm_alpha "
      << number(d.baseline.parameters.at("msm_alpha")) << (d.baseline.alpha_fitted ? " (fitted)" : " (held)") << ", "
      << d.baseline.steps_per_frame << (d.baseline.steps_per_frame == 1 ? " step" : " steps")
      << " per frame, cluster radius " << number(d.baseline.cluster_radius_factor) << ", held-out rms "
      << number(d.baseline.rms) << " " << length_unit << ", noise " << number(d.noise_rms) << " " << length_unit
      << "\n";
  if (d.verdict == "missing_physics" && d.effect != "unknown") {
    out << "  with " << d.effect << ": msm_beta " << number(d.augmented.parameters.at("msm_beta")) << ", held-out rms "
        << number(d.augmented.rms) << " " << length_unit << " (improvement " << number(100.0 * d.improvement)
        << " %)\n";
  }
  out << "  " << d.explanation << "\n";
  return out.str();
}

}  // namespace pliant::host
