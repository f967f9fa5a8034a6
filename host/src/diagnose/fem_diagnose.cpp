#include "pliant/host/diagnose/fem_diagnose.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <thread>

#include "pliant/host/diagnose/effects.hpp"
#include "pliant/host/diagnose/fem_effects.hpp"
#include "pliant/host/diagnose/fem_model_run.hpp"
#include "pliant/host/diagnose/holdout.hpp"
#include "pliant/host/diagnose/locate.hpp"
#include "pliant/host/diagnose/model_run.hpp"
#include "pliant/host/diagnose/noise_floor.hpp"
#include "pliant/host/parallel_fits.hpp"
#include "pliant/host/diagnose/residual_field.hpp"
#include "pliant/host/fem/cylinder_mesh.hpp"
#include "pliant/host/diagnose/selection.hpp"
#include "pliant/host/least_squares_fit.hpp"
#include "pliant/host/diagnose/engine.hpp"
#include "words.hpp"

namespace pliant::host {
namespace {

using words::id_list;
using words::number;

constexpr double kQuasiStaticRatio = 10.0;  // loading time / lowest period above which statics hold
constexpr int kMaxSolvedFrames = 40;        // quasi-static: frames solved per simulation, at most about
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

std::size_t at(int i) { return static_cast<std::size_t>(i); }
std::size_t at(long i) { return static_cast<std::size_t>(i); }

// Pressure-like modulus in readable units.
std::string modulus(double pa) {
  if (pa >= 1e9) return number(pa / 1e9) + " GPa";
  if (pa >= 1e6) return number(pa / 1e6) + " MPa";
  if (pa >= 1e3) return number(pa / 1e3) + " kPa";
  return number(pa) + " Pa";
}

// Sums over held-out and fitting residuals. chi2 terms are whitened; *_ss are raw.
struct FemScore {
  double fit_chi2 = 0;
  long fit_count = 0;
  double held_chi2 = 0;
  long held_count = 0;
  double held_position_ss = 0;
  long held_pairs = 0;
  double held_force_ss = 0;
  long held_force_frames = 0;
  double chi() const { return held_count > 0 ? std::sqrt(held_chi2 / static_cast<double>(held_count)) : 0.0; }
  double rms() const { return held_pairs > 0 ? std::sqrt(held_position_ss / static_cast<double>(held_pairs)) : kNaN; }
  double force_rms() const {
    return held_force_frames > 0 ? std::sqrt(held_force_ss / static_cast<double>(held_force_frames)) : kNaN;
  }
};

class FemScorer {
 public:
  FemScorer(const Recording& recording, const FemRecordingSimulator& simulator, std::vector<unsigned char> held_out,
            double position_std, double force_std)
      : recording_(recording), held_out_(std::move(held_out)), position_std_(position_std), force_std_(force_std) {
    const int frames = recording.frame_count();
    const int n = recording.particle_count;
    const std::vector<unsigned char> compared = compared_pairs(recording);
    const std::vector<unsigned char>& solved = simulator.solved();
    const std::vector<unsigned char>& measured = simulator.force_measured();
    const std::vector<double>& force = simulator.measured_force();
    for (int k = 0; k < frames; ++k) {
      if (solved[at(k)] == 0) continue;
      for (int i = 0; i < n; ++i) {
        const std::size_t pair = at(k) * at(n) + at(i);
        if (compared[pair] != 0) pairs_.push_back(static_cast<long>(pair));
      }
      if (measured[at(k)] != 0 && std::isfinite(force[at(k) * 3]) && std::isfinite(force[at(k) * 3 + 1]) &&
          std::isfinite(force[at(k) * 3 + 2])) {
        force_frames_.push_back(k);
      }
    }
    measured_force_ = force;
    for (long pair : pairs_) fit_count_ += held(static_cast<int>(pair / n)) ? 0 : 3;
    for (int k : force_frames_) fit_count_ += held(k) ? 0 : 3;
  }

  bool held(int frame) const { return held_out_[at(frame)] != 0; }
  bool positions_compared() const { return !pairs_.empty(); }
  bool force_compared() const { return !force_frames_.empty(); }
  const std::vector<int>& force_frames() const { return force_frames_; }
  const std::vector<unsigned char>& held_out() const { return held_out_; }
  long fit_count() const { return fit_count_; }
  double position_std() const { return position_std_; }
  double force_std() const { return force_std_; }
  const std::vector<double>& measured_force() const { return measured_force_; }

  FemScore score(const FemRun& run) const {
    FemScore s;
    const int n = recording_.particle_count;
    for (long pair : pairs_) {
      const int frame = static_cast<int>(pair / n);
      double squared = 0;
      for (int d = 0; d < 3; ++d) {
        const double r = run.positions[at(pair) * 3 + at(d)] - recording_.positions[at(pair) * 3 + at(d)];
        squared += r * r;
      }
      if (!std::isfinite(squared)) squared = 0;
      const double chi2 = squared / (position_std_ * position_std_);
      if (held(frame)) {
        s.held_chi2 += chi2;
        s.held_count += 3;
        s.held_position_ss += squared;
        ++s.held_pairs;
      } else {
        s.fit_chi2 += chi2;
        s.fit_count += 3;
      }
    }
    for (int k : force_frames_) {
      double squared = 0;
      for (int d = 0; d < 3; ++d) {
        const double r = run.force[at(k) * 3 + at(d)] - measured_force_[at(k) * 3 + at(d)];
        squared += r * r;
      }
      if (!std::isfinite(squared)) squared = 0;
      const double chi2 = squared / (force_std_ * force_std_);
      if (held(k)) {
        s.held_chi2 += chi2;
        s.held_count += 3;
        s.held_force_ss += squared;
        ++s.held_force_frames;
      } else {
        s.fit_chi2 += chi2;
        s.fit_count += 3;
      }
    }
    return s;
  }

  /// Held-out whitened squared residuals and their scalar count per held-out block, in frame
  /// order (what the block bootstrap of selection.hpp resamples).
  std::vector<HeldBlock> held_blocks(const FemRun& run) const {
    int block_count = 0;
    const std::vector<int> block_of = held_block_of_frame(held_out_, block_count);
    std::vector<HeldBlock> blocks(at(block_count));
    const int n = recording_.particle_count;
    auto add = [&](int frame, double squared, double std) {
      if (block_of[at(frame)] < 0) return;
      HeldBlock& b = blocks[at(block_of[at(frame)])];
      b.rss += std::isfinite(squared) ? squared / (std * std) : 0.0;
      b.count += 3;
    };
    for (long pair : pairs_) {
      double squared = 0;
      for (int d = 0; d < 3; ++d) {
        const double r = run.positions[at(pair) * 3 + at(d)] - recording_.positions[at(pair) * 3 + at(d)];
        squared += r * r;
      }
      add(static_cast<int>(pair / n), squared, position_std_);
    }
    for (int k : force_frames_) {
      double squared = 0;
      for (int d = 0; d < 3; ++d) {
        const double r = run.force[at(k) * 3 + at(d)] - measured_force_[at(k) * 3 + at(d)];
        squared += r * r;
      }
      add(k, squared, force_std_);
    }
    return blocks;
  }

  /// Whitened fitting residuals in a fixed order (positions, then forces).
  Eigen::VectorXd fit_residuals(const FemRun& run) const {
    Eigen::VectorXd r(fit_count_);
    Eigen::Index row = 0;
    const int n = recording_.particle_count;
    for (long pair : pairs_) {
      if (held(static_cast<int>(pair / n))) continue;
      for (int d = 0; d < 3; ++d) {
        const double v =
            (run.positions[at(pair) * 3 + at(d)] - recording_.positions[at(pair) * 3 + at(d)]) / position_std_;
        r(row++) = std::isfinite(v) ? v : 0.0;
      }
    }
    for (int k : force_frames_) {
      if (held(k)) continue;
      for (int d = 0; d < 3; ++d) {
        const double v = (run.force[at(k) * 3 + at(d)] - measured_force_[at(k) * 3 + at(d)]) / force_std_;
        r(row++) = std::isfinite(v) ? v : 0.0;
      }
    }
    return r;
  }

  /// Closed-form modulus scale: the factor c minimising sum over fitting force frames of
  /// |c F_sim - F_meas|^2 (positions do not depend on it). 0 when no force is compared.
  double force_scale(const FemRun& run, double* normal = nullptr) const {
    double ab = 0;
    double aa = 0;
    for (int k : force_frames_) {
      if (held(k)) continue;
      for (int d = 0; d < 3; ++d) {
        const double a = run.force[at(k) * 3 + at(d)] / force_std_;
        const double b = measured_force_[at(k) * 3 + at(d)] / force_std_;
        if (!std::isfinite(a) || !std::isfinite(b)) continue;
        ab += a * b;
        aa += a * a;
      }
    }
    if (normal != nullptr) *normal = aa;
    return aa > 0 ? ab / aa : 0.0;
  }

 private:
  const Recording& recording_;
  std::vector<unsigned char> held_out_;
  double position_std_ = 1;
  double force_std_ = 1;
  std::vector<long> pairs_;        // compared (frame * n + id) on solved frames
  std::vector<int> force_frames_;  // solved frames with a measured force
  std::vector<double> measured_force_;
  long fit_count_ = 0;
};

struct FemFit {
  bool ok = false;
  std::vector<double> values;  // physical effect parameters
  std::vector<double> std;     // one per effect parameter (inf when not identified)
  double youngs = 0;
  double youngs_std = kInf;
  FemRun run;
  FemScore score;
  Eigen::VectorXd fit_residuals;  // whitened, FemScorer::fit_residuals order
  std::vector<HeldBlock> held_blocks;
  int fitted = 0;  // E and the effect's parameters
};

class FemFitter {
 public:
  FemFitter(FemRecordingSimulator& simulator, const FemScorer& scorer, const FemEffectContext& context)
      : simulator_(simulator), scorer_(scorer), context_(context) {}

  FemRunSettings settings(const FemEffect* effect, const std::vector<double>& values, double youngs) const {
    FemRunSettings s;
    s.youngs_modulus_pa = youngs;
    if (effect != nullptr) effect->apply(values, context_, s);
    return s;
  }

  /// True when E follows in closed form (positions independent of E, force proportional). A
  /// body-force effect is profiled at a fixed ratio of body acceleration to E: its parameters
  /// are then simulated at the given E and mapped to physical values by evaluate().
  bool profiled(const FemEffect* effect) const {
    if (effect != nullptr && effect->body_force) return simulator_.scale_invariant_at_fixed_gravity_ratio();
    return simulator_.scale_invariant(FemRunSettings{});
  }

  struct Evaluation {
    bool ok = false;
    FemRun run;
    double youngs = 0;
    std::vector<double> values;  // physical effect parameters of the run (after profiling)
    Eigen::VectorXd residuals;
  };

  // One simulation at (values, youngs); with `profile` and a profiled effect, E is replaced by
  // its closed-form optimum (the run's forces rescaled). Unless `all_frames`, an effect without
  // history is simulated on the fitting frames only (the residuals do not change: held-out
  // frames are not in them).
  Evaluation evaluate(const FemEffect* effect, const std::vector<double>& values, double youngs, bool profile,
                      bool all_frames = false) {
    Evaluation ev;
    ++simulations;
    const bool fitting_only = !all_frames && (effect == nullptr || !effect->history);
    ev.run = simulator_.simulate(settings(effect, values, youngs), fitting_only);
    ev.youngs = youngs;
    ev.values = values;
    ev.ok = ev.run.ok;
    if (!ev.ok) return ev;
    if (profile && profiled(effect) && scorer_.force_compared()) {
      const double scale = scorer_.force_scale(ev.run);
      if (scale > 0) {
        for (double& f : ev.run.force) f *= scale;
        ev.youngs = youngs * scale;
        if (effect != nullptr && effect->body_force) {
          // The run at (E, g_declared + g) is the run at (c E, c (g_declared + g)) with forces
          // divided by c: the physical extra acceleration is c (g_declared + g) - g_declared.
          const Eigen::Vector3d declared = simulator_.declared_gravity_m_s2();
          for (int a = 0; a < 3; ++a) ev.values[at(a)] = scale * (declared(a) + values[at(a)]) - declared(a);
        }
      }
    }
    ev.residuals = scorer_.fit_residuals(ev.run);
    return ev;
  }

  // E refitted with the effect parameters held: closed form when profiled, else two
  // Gauss-Newton steps on log E.
  Evaluation profile(const FemEffect* effect, const std::vector<double>& values, double youngs) {
    Evaluation best = evaluate(effect, values, youngs, true);
    if (profiled(effect) || !best.ok) return best;
    for (int iteration = 0; iteration < 2; ++iteration) {
      const double h = 0.01;
      const Evaluation probe = evaluate(effect, values, best.youngs * std::exp(h), false);
      if (!probe.ok) break;
      const Eigen::VectorXd j = (probe.residuals - best.residuals) / h;
      const double jj = j.squaredNorm();
      if (!(jj > 0)) break;
      const double step = std::clamp(-j.dot(best.residuals) / jj, -1.0, 1.0);
      const Evaluation trial = evaluate(effect, values, best.youngs * std::exp(step), false);
      if (!trial.ok || !(trial.residuals.squaredNorm() < best.residuals.squaredNorm())) break;
      best = trial;
    }
    return best;
  }

  // Grid over the scanned parameters (E profiled at every point), then bounded
  // Levenberg-Marquardt (fit_least_squares) on all parameters from the best grid points.
  FemFit fit(const FemEffect* effect, double start_youngs) {
    std::vector<double> start_u;
    std::vector<int> scanned;
    for (std::size_t p = 0; p < effect->parameters.size(); ++p) {
      const EffectParameter& parameter = effect->parameters[p];
      start_u.push_back(std::isfinite(parameter.null_value) ? parameter.coordinate(parameter.null_value) : 0.5);
      if (parameter.scanned) scanned.push_back(static_cast<int>(p));
    }
    struct Seed {
      std::vector<double> u;
      double cost;
      double youngs;
    };
    std::vector<Seed> seeds;
    const int per_axis = scanned.size() <= 1 ? 7 : (scanned.size() == 2 ? 5 : 4);
    long points = 1;
    for (std::size_t a = 0; a < scanned.size(); ++a) points *= per_axis;
    for (long index = 0; index < points; ++index) {
      std::vector<double> u = start_u;
      long rest = index;
      for (int c : scanned) {
        u[at(c)] = static_cast<double>(rest % per_axis) / (per_axis - 1);
        rest /= per_axis;
      }
      const Evaluation ev = profile(effect, physical(effect, u), start_youngs);
      if (ev.ok) seeds.push_back({u, ev.residuals.squaredNorm(), ev.youngs});
    }
    FemFit best;
    if (seeds.empty()) return best;
    std::sort(seeds.begin(), seeds.end(), [](const Seed& a, const Seed& b) { return a.cost < b.cost; });
    // Two starts where the grid spans two parameters (profiled runs only: they cost one simulation).
    const std::size_t starts = std::min<std::size_t>(seeds.size(), profiled(effect) && scanned.size() >= 2 ? 2 : 1);
    double best_cost = kInf;
    std::vector<double> best_values = physical(effect, seeds.front().u);
    double best_youngs = seeds.front().youngs;
    FitResult best_result;
    bool have_result = false;
    for (std::size_t s = 0; s < starts; ++s) {
      FitResult result;
      if (!levenberg_marquardt(effect, seeds[s].u, seeds[s].youngs, result)) continue;
      if (2.0 * result.final_cost < best_cost) {
        best_cost = 2.0 * result.final_cost;
        best_values.assign(result.values.begin(), result.values.begin() + static_cast<long>(effect->parameters.size()));
        best_youngs = profiled(effect) ? seeds[s].youngs : result.values.back();
        best_result = result;
        have_result = true;
      }
    }
    if (!have_result && seeds.front().cost < kInf) {
      best_values = physical(effect, seeds.front().u);
      best_youngs = seeds.front().youngs;
    }
    return finish(effect, best_values, best_youngs, have_result ? &best_result : nullptr);
  }

  // Final evaluation, uncertainties and BIC.
  FemFit finish(const FemEffect* effect, const std::vector<double>& values, double youngs, const FitResult* result) {
    FemFit f;
    const Evaluation ev = evaluate(effect, values, youngs, profiled(effect), true);
    f.ok = ev.ok;
    if (!ev.ok) return f;
    f.values = ev.values;
    f.youngs = ev.youngs;
    f.run = ev.run;
    f.score = scorer_.score(ev.run);
    const std::size_t parameters = effect != nullptr ? effect->parameters.size() : 0;
    f.std.assign(parameters, kInf);
    if (result != nullptr) {
      // Profiled body forces were fitted at the simulated E: their physical values scale by c.
      const double scale = effect != nullptr && effect->body_force && profiled(effect) ? ev.youngs / youngs : 1.0;
      for (std::size_t p = 0; p < parameters && p < result->standard_deviations.size(); ++p) {
        const double s = scale * result->standard_deviations[p];
        f.std[p] = std::isfinite(s) && s > 0 ? s : kInf;
      }
      if (!profiled(effect) && result->standard_deviations.size() > parameters) {
        const double s = result->standard_deviations[parameters];
        f.youngs_std = std::isfinite(s) && s > 0 ? s : kInf;
      }
    }
    const double n = static_cast<double>(scorer_.fit_count());
    const double rss = ev.residuals.squaredNorm();
    const double fitted = 1.0 + static_cast<double>(parameters);
    if (profiled(effect)) {
      // E from the linear least-squares fit of the forces: std = s / sqrt(a.a) in units of E.
      double normal = 0;
      FemRun unit = ev.run;
      for (double& v : unit.force) v /= ev.youngs;
      scorer_.force_scale(unit, &normal);
      const double s2 = n > fitted ? rss / (n - fitted) : 0.0;
      if (normal > 0) f.youngs_std = std::sqrt(s2 / normal);
    }
    f.fit_residuals = ev.residuals;
    f.held_blocks = scorer_.held_blocks(ev.run);
    f.fitted = static_cast<int>(fitted);
    return f;
  }

  std::vector<double> physical(const FemEffect* effect, const std::vector<double>& u) const {
    std::vector<double> values;
    for (std::size_t p = 0; p < effect->parameters.size(); ++p) values.push_back(effect->parameters[p].value(u[p]));
    return values;
  }

  int simulations = 0;

 private:
  bool levenberg_marquardt(const FemEffect* effect, const std::vector<double>& u, double youngs, FitResult& result) {
    std::vector<FitParameter> parameters;
    for (std::size_t p = 0; p < effect->parameters.size(); ++p) {
      const EffectParameter& ep = effect->parameters[p];
      FitParameter fp;
      fp.name = ep.name;
      fp.lower = ep.lower;
      fp.upper = ep.upper;
      fp.log_scale = ep.scale == Scale::logarithmic;
      const double margin = 2e-3;
      fp.initial = fp.log_scale ? ep.lower * std::pow(ep.upper / ep.lower, std::clamp(u[p], margin, 1.0 - margin))
                                : std::clamp(ep.value(u[p]), ep.lower + margin * (ep.upper - ep.lower),
                                             ep.upper - margin * (ep.upper - ep.lower));
      parameters.push_back(fp);
    }
    const bool with_youngs = !profiled(effect);
    if (with_youngs) parameters.push_back({"youngs_modulus", youngs, youngs / 10.0, youngs * 10.0, true});
    const std::size_t count = effect->parameters.size();
    const ResidualFunction function = [&](const std::vector<double>& values, std::vector<double>& residuals) {
      const std::vector<double> effect_values(values.begin(), values.begin() + static_cast<long>(count));
      const Evaluation ev = evaluate(effect, effect_values, with_youngs ? values.back() : youngs, !with_youngs);
      if (!ev.ok || ev.residuals.size() != static_cast<Eigen::Index>(residuals.size())) return false;
      for (std::size_t i = 0; i < residuals.size(); ++i) residuals[i] = ev.residuals(static_cast<Eigen::Index>(i));
      return true;
    };
    // Every evaluation is a simulation: forward differences (p + 1 simulations per Jacobian)
    // and a small iteration budget. A relative gain of 1e-4 moves a BIC by 1e-4 of the residual
    // count: the fit is then settled as far as selection is concerned.
    FitOptions options;
    options.loss = RobustLoss::none;
    options.central_differences = false;
    options.difference_step = 1e-3;
    options.max_iterations = with_youngs ? 8 : 10;
    options.function_tolerance = 1e-4;
    options.parameter_tolerance = 1e-6;
    options.initial_damping = 1e-3;
    options.projected_line_search = false;
    try {
      result = fit_least_squares(parameters, static_cast<int>(scorer_.fit_count()), function, options);
    } catch (const std::exception&) {
      return false;  // the model fails at the start: the grid point stays the fit
    }
    return std::isfinite(result.final_cost);
  }

  FemRecordingSimulator& simulator_;
  const FemScorer& scorer_;
  const FemEffectContext& context_;
};

// A fit as selection sees it (selection.hpp): E is a nuisance coordinate; an effect's
// parameters are tested against their nulls. A fit that could not be simulated is never named.
FitEvidence evidence_of(const FemFit& fit, const FemEffect* effect) {
  FitEvidence evidence;
  evidence.ok = fit.ok;
  if (!fit.ok) return evidence;
  evidence.fit_residuals = fit.fit_residuals;
  evidence.fitted = fit.fitted;
  evidence.held_blocks = fit.held_blocks;
  evidence.values = fit.values;
  evidence.std = fit.std;
  for (std::size_t p = 0; effect != nullptr && p < effect->parameters.size(); ++p) {
    evidence.nulls.push_back(effect->parameters[p].null_value);
  }
  return evidence;
}

// Fills NaN frames of a frame-major array (values_per_frame entries each) by linear
// interpolation in time between the nearest frames that have values (held at the ends).
std::vector<double> fill_frames(const std::vector<double>& values, const std::vector<double>& times,
                                const std::vector<unsigned char>& solved, std::size_t per_frame) {
  std::vector<double> out = values;
  std::vector<int> known;
  for (std::size_t k = 0; k < solved.size(); ++k) {
    if (solved[k] != 0) known.push_back(static_cast<int>(k));
  }
  if (known.empty()) return out;
  for (int k = 0; k < static_cast<int>(solved.size()); ++k) {
    if (solved[at(k)] != 0) continue;
    const auto upper = std::upper_bound(known.begin(), known.end(), k);
    const int hi = upper == known.end() ? known.back() : *upper;
    const int lo = upper == known.begin() ? known.front() : *(upper - 1);
    const double span = times[at(hi)] - times[at(lo)];
    const double s = hi != lo && span > 0 ? (times[at(k)] - times[at(lo)]) / span : 0.0;
    for (std::size_t j = 0; j < per_frame; ++j) {
      out[at(k) * per_frame + j] = (1.0 - s) * values[at(lo) * per_frame + j] + s * values[at(hi) * per_frame + j];
    }
  }
  return out;
}

// Largest element strain of a run (the deformation the material saw).
double peak_strain(const FemRun& run, const Recording& recording, const std::vector<unsigned char>& solved) {
  if (!recording.mesh) return 0.0;
  const TetMesh& mesh = *recording.mesh;
  const int n = recording.particle_count;
  double peak = 0;
  for (int k = 0; k < static_cast<int>(solved.size()); ++k) {
    if (solved[at(k)] == 0) continue;
    for (int e = 0; e < mesh.tet_count(); ++e) {
      Eigen::Matrix3d dm;
      Eigen::Matrix3d ds;
      const int* t = &mesh.tetrahedra[at(e) * 4];
      for (int c = 0; c < 3; ++c) {
        for (int a = 0; a < 3; ++a) {
          dm(a, c) = mesh.points[at(t[c + 1]) * 3 + at(a)] - mesh.points[at(t[0]) * 3 + at(a)];
          ds(a, c) = run.positions[(at(k) * at(n) + at(t[c + 1])) * 3 + at(a)] -
                     run.positions[(at(k) * at(n) + at(t[0])) * 3 + at(a)];
        }
      }
      const Eigen::Matrix3d f = ds * dm.inverse();
      const Eigen::JacobiSVD<Eigen::Matrix3d> svd(f);
      const Eigen::Vector3d stretch = svd.singularValues();
      const Eigen::Vector3d strain = stretch - Eigen::Vector3d::Ones();
      const Eigen::Vector3d deviator = strain - Eigen::Vector3d::Constant(strain.sum() / 3.0);
      const double value = std::sqrt(2.0 / 3.0) * deviator.norm();
      if (std::isfinite(value)) peak = std::max(peak, value);
    }
  }
  return peak;
}

// The run of solved force frames where the force residual is clearly above noise (per
// component rms over 3 noise std), gaps of up to two frames bridged, with the largest excess.
Location force_location(const FemScorer& scorer, const FemRun& run, const std::vector<double>& times,
                        const std::vector<int>& applied_to) {
  Location location;
  const double threshold = 9.0 * 3.0;  // |r|^2 / sigma^2 over 3 components
  const std::vector<int>& frames = scorer.force_frames();
  const std::vector<double>& measured = scorer.measured_force();
  std::vector<double> excess(frames.size(), 0.0);
  for (std::size_t j = 0; j < frames.size(); ++j) {
    double squared = 0;
    for (int d = 0; d < 3; ++d) {
      const double r = run.force[at(frames[j]) * 3 + at(d)] - measured[at(frames[j]) * 3 + at(d)];
      squared += r * r;
    }
    squared /= scorer.force_std() * scorer.force_std();
    excess[j] = std::isfinite(squared) ? squared - threshold : 0.0;
  }
  double best = 0;
  std::size_t j = 0;
  while (j < frames.size()) {
    if (excess[j] <= 0) {
      ++j;
      continue;
    }
    std::size_t end = j;
    double sum = 0;
    std::size_t gap = 0;
    for (std::size_t i = j; i < frames.size(); ++i) {
      if (excess[i] > 0) {
        sum += excess[i];
        end = i;
        gap = 0;
      } else if (++gap > 2) {
        break;
      }
    }
    if (sum > best) {
      best = sum;
      location.t_start = times[at(frames[j])];
      location.t_end = times[at(frames[end])];
      location.particles = applied_to;
    }
    j = end + 1;
  }
  return location;
}

// Stiffening signature: the baseline force residual along the load direction has opposite
// signs at small (0.1-0.5 of the peak) and large (above 0.75 of the peak) load, each mean 3
// standard errors from 0; min/max of their magnitudes, else 0.
double force_load_sign_change(const FemScorer& scorer, const FemRun& run) {
  const std::vector<int>& frames = scorer.force_frames();
  const std::vector<double>& measured = scorer.measured_force();
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  double peak = 0;
  for (int k : frames) {
    const Eigen::Vector3d f(measured[at(k) * 3], measured[at(k) * 3 + 1], measured[at(k) * 3 + 2]);
    if (f.norm() > peak) {
      peak = f.norm();
      direction = f / f.norm();
    }
  }
  if (!(peak > 3.0 * scorer.force_std())) return 0.0;
  double small_sum = 0;
  double large_sum = 0;
  int small_count = 0;
  int large_count = 0;
  for (int k : frames) {
    const Eigen::Vector3d f(measured[at(k) * 3], measured[at(k) * 3 + 1], measured[at(k) * 3 + 2]);
    const Eigen::Vector3d s(run.force[at(k) * 3], run.force[at(k) * 3 + 1], run.force[at(k) * 3 + 2]);
    const double load = f.dot(direction);
    const double r = (f - s).dot(direction);
    if (!std::isfinite(r)) continue;
    if (load > 0.1 * peak && load <= 0.5 * peak) {
      small_sum += r;
      ++small_count;
    } else if (load > 0.75 * peak) {
      large_sum += r;
      ++large_count;
    }
  }
  if (small_count == 0 || large_count == 0) return 0.0;
  const double small = small_sum / small_count;
  const double large = large_sum / large_count;
  const double sigma = scorer.force_std();
  if (std::abs(small) <= 3.0 * sigma / std::sqrt(small_count) ||
      std::abs(large) <= 3.0 * sigma / std::sqrt(large_count))
    return 0.0;
  if (small * large >= 0) return 0.0;
  return std::min(std::abs(small), std::abs(large)) / std::max(std::abs(small), std::abs(large));
}

// Whether the drive or the load falls back after its peak (by 20 % of it, peak before the end).
bool unloads(const Recording& recording) {
  std::vector<double> level(at(recording.frame_count()), 0.0);
  const std::vector<double>& rest = recording.rest_positions;
  for (int k = 0; k < recording.frame_count(); ++k) {
    for (const DrivenWindow& w : recording.driven) {
      if (!w.active_at(recording.frame_times_s[at(k)]) || !recording.observed(k, w.id)) continue;
      double squared = 0;
      for (int d = 0; d < recording.dimension; ++d) {
        const double delta = recording.position(k, w.id, d) - rest[at(w.id) * at(recording.dimension) + at(d)];
        squared += delta * delta;
      }
      level[at(k)] = std::max(level[at(k)], std::sqrt(squared));
    }
  }
  auto falls_back = [](const std::vector<double>& series) {
    double peak = 0;
    std::size_t where = 0;
    for (std::size_t k = 0; k < series.size(); ++k) {
      if (series[k] > peak) {
        peak = series[k];
        where = k;
      }
    }
    if (!(peak > 0)) return false;
    double after = peak;
    for (std::size_t k = where; k < series.size(); ++k) after = std::min(after, series[k]);
    return after < 0.8 * peak;
  };
  if (falls_back(level)) return true;
  std::vector<double> force;
  for (const WrenchSample& s : recording.wrench) {
    force.push_back(std::sqrt(s.force_n[0] * s.force_n[0] + s.force_n[1] * s.force_n[1] + s.force_n[2] * s.force_n[2]));
  }
  return falls_back(force);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<long>(mid), values.end());
  return values[mid];
}

}  // namespace

double estimate_force_noise_std(const Recording& recording) {
  const std::vector<WrenchSample>& samples = recording.wrench;
  const int count = static_cast<int>(samples.size());
  if (count < 5) return 0.0;
  std::vector<double> scaled;
  for (int axis = 0; axis < 3; ++axis) {
    bool constant = true;
    for (const WrenchSample& s : samples) constant = constant && s.force_n[axis] == samples.front().force_n[axis];
    if (constant) continue;
    for (int k = 0; k < count; ++k) {
      const int width = std::min(7, count);
      const int first = std::clamp(k - width / 2, 0, count - width);
      const int degree = std::min(3, width - 2);
      const double t0 = samples[at(k)].t_s;
      const double span = std::max(samples[at(first + width - 1)].t_s - samples[at(first)].t_s, 1e-12);
      Eigen::MatrixXd design(width, degree + 1);
      Eigen::VectorXd y(width);
      for (int i = 0; i < width; ++i) {
        const double t = (samples[at(first + i)].t_s - t0) / span;
        double power = 1;
        for (int p = 0; p <= degree; ++p) {
          design(i, p) = power;
          power *= t;
        }
        y(i) = samples[at(first + i)].force_n[axis];
      }
      const Eigen::MatrixXd gram = design.transpose() * design;
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(gram);
      const Eigen::VectorXd coefficients = ldlt.solve(design.transpose() * y);
      const int row = k - first;
      const double fitted = design.row(row).dot(coefficients);
      const double leverage = design.row(row).dot(ldlt.solve(design.row(row).transpose()));
      if (!(leverage < 1.0 - 1e-9)) continue;
      const double value = (y(row) - fitted) / std::sqrt(1.0 - leverage);
      if (std::isfinite(value)) scaled.push_back(std::abs(value));
    }
  }
  return scaled.empty() ? 0.0 : 1.4826 * median(scaled);
}

namespace {

// Object size: the largest extent of the rest shape over the axes (1 when it has none).
double object_size(const Recording& recording) {
  double size = 0;
  for (int d = 0; d < 3; ++d) {
    double lo = kInf;
    double hi = -kInf;
    for (int i = 0; i < recording.particle_count; ++i) {
      lo = std::min(lo, recording.rest_positions[at(i) * 3 + at(d)]);
      hi = std::max(hi, recording.rest_positions[at(i) * 3 + at(d)]);
    }
    size = std::max(size, hi - lo);
  }
  return size > 0 ? size : 1.0;
}

// Position noise from the tracks that are compared (observed and not driven): driven tracks
// may be exact (a programmed tool path, platen positions derived from a crosshead reading) and
// would pull the median of the noise floor to zero.
double compared_position_noise_std(const Recording& recording) {
  const std::vector<unsigned char> compared = compared_pairs(recording);
  if (std::find(compared.begin(), compared.end(), 1) == compared.end()) return 0.0;
  Recording tracks;
  tracks.dimension = 3;
  tracks.particle_count = recording.particle_count;
  tracks.frame_times_s = recording.frame_times_s;
  tracks.positions = recording.positions;
  for (std::size_t pair = 0; pair < compared.size(); ++pair) {
    if (compared[pair] != 0) continue;
    for (std::size_t d = 0; d < 3; ++d) tracks.positions[pair * 3 + d] = kNaN;
  }
  return estimate_noise_std(tracks);
}

double force_noise_floor(const Recording& recording) {
  double peak_force = 0;
  for (const WrenchSample& s : recording.wrench) {
    peak_force = std::max(
        peak_force, std::sqrt(s.force_n[0] * s.force_n[0] + s.force_n[1] * s.force_n[1] + s.force_n[2] * s.force_n[2]));
  }
  return std::max(estimate_force_noise_std(recording), 1e-6 * std::max(peak_force, 1.0));
}

// Heterogeneity's patches of elements: nodes in spatial patches, each element in the patch most
// of its corners belong to (ties: the first corner's); the reference patch has the most volume.
void describe_patches(const Recording& recording, FemEffectContext& context) {
  const int n = recording.particle_count;
  const std::vector<std::vector<int>> patches = spatial_patches(
      recording.rest_positions, 3, std::max(6, (n - static_cast<int>(recording.fixed.size())) / 8), recording.fixed);
  std::vector<int> node_patch(at(n), 0);
  for (std::size_t p = 0; p < patches.size(); ++p) {
    for (int id : patches[p]) node_patch[at(id)] = static_cast<int>(p);
  }
  context.patch_count = static_cast<int>(patches.size());
  std::vector<double> volume(patches.size(), 0.0);
  const TetMesh& mesh = *recording.mesh;
  for (int e = 0; e < mesh.tet_count(); ++e) {
    int best = node_patch[at(mesh.tetrahedra[at(e) * 4])];
    int best_votes = 0;
    for (int c = 0; c < 4; ++c) {
      const int p = node_patch[at(mesh.tetrahedra[at(e) * 4 + at(c)])];
      int votes = 0;
      for (int c2 = 0; c2 < 4; ++c2) votes += node_patch[at(mesh.tetrahedra[at(e) * 4 + at(c2)])] == p ? 1 : 0;
      if (votes > best_votes) {
        best_votes = votes;
        best = p;
      }
    }
    context.element_patch.push_back(best);
    volume[at(best)] += std::abs(tet_signed_volume(mesh, e));
  }
  context.reference_patch = static_cast<int>(std::max_element(volume.begin(), volume.end()) - volume.begin());
}

// What a named effect's parameters mean, in a sentence ("" when there is nothing to add).
std::string effect_detail(const FemEffect& effect, const FemFit& f, const FemEffectContext& context) {
  std::ostringstream text;
  if (effect.name == "stiffening") {
    const double k = f.values[0];
    const double eps = context.peak_strain;
    text << " Stress grows faster than strain: the best single modulus is too stiff at small strain and too soft at "
            "large strain; with k = "
         << number(k) << " the modulus at the peak strain " << number(eps) << " is "
         << number(std::exp(std::min(k * eps * eps, 12.0))) << " times its small-strain value.";
  } else if (effect.name == "latency") {
    const double tau = f.values[0];
    text << " The wrench stream " << (tau >= 0 ? "lags" : "leads") << " the positions by " << number(std::abs(tau))
         << " s.";
  } else if (effect.name == "viscosity" && context.force_measured) {
    text << " The force relaxes: the instantaneous modulus is " << number(1.0 + f.values[0])
         << " times the long-term one, with time constant " << number(f.values[1]) << " s.";
  } else if (effect.name == "gravity") {
    text << " A body acceleration of (" << number(f.values[0]) << ", " << number(f.values[1]) << ", "
         << number(f.values[2]) << ") m/s^2 acts that the recording does not declare.";
  } else if (effect.name == "friction") {
    const double slip = f.values[0];
    text << " The supports slide on their plane";
    if (slip >= 1.0) {
      text << " without friction.";
    } else {
      text << " with a friction coefficient of " << number(1.0 / slip - 1.0) << ".";
    }
  } else if (effect.name == "plasticity") {
    text << " Above an equivalent strain of " << number(f.values[0]) << " the rest shape creeps at "
         << number(f.values[1]) << " /s: a permanent set.";
  } else if (effect.name == "heterogeneity") {
    std::vector<std::string> parts;
    std::size_t k = 0;
    for (int p = 0; p < context.patch_count; ++p) {
      if (p == context.reference_patch) continue;
      const double factor = f.values[k];
      const double s = f.std[k];
      ++k;
      if (std::isfinite(s) && std::abs(factor - 1.0) >= SelectionRules{}.min_significance * s) {
        parts.push_back("patch " + std::to_string(p + 1) + " x" + number(factor));
      }
    }
    if (!parts.empty()) {
      text << " Modulus relative to the largest patch:";
      for (std::size_t i = 0; i < parts.size(); ++i) text << (i == 0 ? " " : ", ") << parts[i];
      text << ".";
    }
  }
  return text.str();
}

// The corotational linear FEM as a diagnosis model (engine.hpp).
class FemDiagnosis final : public DiagnosisModel {
 public:
  FemDiagnosis(const Recording& recording, const DiagnoseOptions& options) : recording_(recording), options_(options) {
    const int frames = recording.frame_count();
    duration_ = recording.frame_times_s.back() - recording.frame_times_s.front();
    // Quasi-static frames solved: every `stride`-th.
    stride_ = options.fem_frame_stride > 0 ? options.fem_frame_stride
                                           : std::max(1, (frames + kMaxSolvedFrames - 1) / kMaxSolvedFrames);
    mode_ = options.fem_time == "dynamic" ? FemTimeMode::dynamic : FemTimeMode::quasi_static;
    simulator_ = make_simulator(mode_);
    // Held-out blocks of about 0.1 s, but at most a sixth of the recording (a fast test of a few
    // tenths of a second still holds out three blocks), at least 3 frames, a whole number of
    // solved strides.
    int block = holdout_block_frames(recording, options.holdout_block_frames, 6);
    const int solved_stride = mode_ == FemTimeMode::quasi_static ? stride_ : 1;
    if (solved_stride > 1) block = solved_stride * std::max(1, (block + solved_stride - 1) / solved_stride);
    held_out_ = interleaved_holdout(frames, block);
    // Fits only look at the fitting frames: quasi-static runs of effects without history solve
    // only those (FemFitter::evaluate).
    fitting_frames_.resize(held_out_.size());
    for (std::size_t k = 0; k < held_out_.size(); ++k) fitting_frames_[k] = held_out_[k] == 0 ? 1 : 0;
    simulator_->set_fitting_frames(fitting_frames_);

    position_std_ = std::max(compared_position_noise_std(recording), 1e-6 * object_size(recording));
    force_std_ = force_noise_floor(recording);
    scorer_ = std::make_unique<FemScorer>(recording, *simulator_, held_out_, position_std_, force_std_);
    if (!scorer_->positions_compared() && !scorer_->force_compared()) {
      throw std::runtime_error(
          "no free node is observed and no wrench is measured at constrained nodes; nothing to compare the FEM with");
    }
    if (!(simulator_->loading_time_s() < kInf) && !scorer_->positions_compared()) {
      throw std::runtime_error("nothing is driven or loaded; there is no deformation to diagnose");
    }
  }

  // E, first quasi-statically; then the time rule: a loading faster than kQuasiStaticRatio
  // lowest natural periods is simulated dynamically and E refitted.
  void fit_baseline(Diagnosis& out) override {
    const double start_youngs =
        simulator_->declared_youngs_modulus_pa() > 0 ? simulator_->declared_youngs_modulus_pa() : 1e5;
    baseline_ = fit_youngs(start_youngs);
    lowest_period_ = simulator_->lowest_period_s(baseline_.youngs);
    loading_time_ = simulator_->loading_time_s();
    // No finite period (every node constrained, or the modes cannot be computed): nothing can
    // vibrate that statics would miss, so the run stays quasi-static.
    if (options_.fem_time == "auto" && std::isfinite(lowest_period_) &&
        loading_time_ < kQuasiStaticRatio * lowest_period_) {
      mode_ = FemTimeMode::dynamic;
      simulator_ = make_simulator(mode_);
      simulator_->set_fitting_frames(fitting_frames_);
      scorer_ = std::make_unique<FemScorer>(recording_, *simulator_, held_out_, position_std_, force_std_);
      baseline_ = fit_youngs(baseline_.youngs);
    }
    if (!baseline_.ok) throw std::runtime_error("the FEM baseline cannot be simulated");
    positions_ = scorer_->positions_compared();
    forces_ = scorer_->force_compared();
    out.noise_rms = positions_ ? position_std_ * std::sqrt(3.0) : kNaN;
    out.force_noise_rms = forces_ ? force_std_ * std::sqrt(3.0) : kNaN;
    out.baseline.model = "fem";
    out.baseline.parameters = {{"youngs_modulus", baseline_.youngs},
                               {"poisson_ratio", simulator_->poisson_ratio()},
                               {"density", simulator_->density_kg_m3()}};
    out.baseline.parameter_std = {{"youngs_modulus", baseline_.youngs_std}};
    out.baseline.rms = baseline_.score.rms();
    out.baseline.force_rms = baseline_.score.force_rms();
  }

  std::map<std::string, double> locate(Diagnosis& out) override {
    const int n = recording_.particle_count;
    const std::vector<unsigned char>& solved = simulator_->solved();
    const bool quasi_static = mode_ == FemTimeMode::quasi_static;
    ResidualField field;
    if (positions_) {
      field = make_residual_field(recording_.positions, baseline_.run.positions, n, 3);
      out.location = locate_mismatch(field, recording_.frame_times_s, position_std_);
    } else {
      out.location =
          force_location(*scorer_, baseline_.run, recording_.frame_times_s,
                         std::vector<int>(recording_.wrench_applied_to.begin(), recording_.wrench_applied_to.end()));
      std::sort(out.location.particles.begin(), out.location.particles.end());
    }
    location_ = out.location;
    std::map<std::string, double> signatures;
    if (positions_ && stride_ == 1 && quasi_static) {
      signatures = residual_signatures(
          recording_, fill_frames(baseline_.run.positions, recording_.frame_times_s, solved, at(n) * 3), field,
          out.location, position_std_);
    }
    if (forces_) signatures["force_load_sign_change"] = force_load_sign_change(*scorer_, baseline_.run);
    signatures["quasi_static"] = quasi_static ? 1.0 : 0.0;
    signatures["lowest_period_s"] = lowest_period_;
    signatures["loading_time_s"] = loading_time_;
    signatures["frame_stride"] = quasi_static ? stride_ : 1;
    return signatures;
  }

  std::vector<std::string> catalogue() override {
    const int frames = recording_.frame_count();
    context_.quasi_static = mode_ == FemTimeMode::quasi_static;
    context_.force_measured = forces_;
    context_.has_wrench = !recording_.wrench.empty() && !recording_.wrench_applied_to.empty();
    context_.positions_compared = positions_;
    context_.unloads = unloads(recording_);
    context_.support_plane = simulator_->has_support_plane();
    context_.duration_s = duration_;
    context_.frame_interval_s = duration_ / std::max(1, (frames - 1) / (context_.quasi_static ? stride_ : 1));
    context_.recording_interval_s = duration_ / std::max(1, frames - 1);
    context_.peak_strain = peak_strain(baseline_.run, recording_, simulator_->solved());
    context_.lowest_omega_rad_s =
        std::isfinite(lowest_period_) && lowest_period_ > 0 ? 2.0 * 3.14159265358979323846 / lowest_period_ : 0.0;
    if (positions_) describe_patches(recording_, context_);
    effects_ = fem_effect_catalogue(context_);
    std::vector<std::string> names;
    for (const FemEffect& e : effects_) names.push_back(e.name);
    return names;
  }

  // Every effect is fitted independently, so the fits run on worker threads, each with its own
  // simulator (a simulator holds the model, solvers and a run cache: one per thread). The
  // result does not depend on the thread count.
  void fit_effects(int threads, const std::function<void()>& one_done) override {
    fits_.assign(effects_.size(), FemFit{});
    std::vector<int> simulations(effects_.size(), 0);
    run_on_workers(
        effects_.size(), worker_count(effects_.size(), threads),
        [&](bool is_caller) {
          std::unique_ptr<FemRecordingSimulator> made;
          if (!is_caller) {
            made = make_simulator(mode_);
            made->set_fitting_frames(fitting_frames_);
          }
          return made;
        },
        [&](std::unique_ptr<FemRecordingSimulator>& made, std::size_t e) {
          FemRecordingSimulator& own = made ? *made : *simulator_;
          FemFitter fitter(own, *scorer_, context_);
          fits_[e] = fitter.fit(&effects_[e], baseline_.youngs);
          simulations[e] = fitter.simulations;
        },
        one_done);
    for (int count : simulations) simulations_ += count;
  }

  FitEvidence baseline_evidence() const override { return evidence_of(baseline_, nullptr); }
  FitEvidence effect_evidence(std::size_t e) const override { return evidence_of(fits_[e], &effects_[e]); }
  double noise_misfit() const override { return 1.0; }  // whitened residuals

  // The whitened residuals are taken as independent (design effect 1): force residuals belong
  // to no particle, so per-particle clusters do not describe them.
  std::vector<int> residual_clusters() const override { return {}; }

  Candidate candidate(std::size_t e, const RankedEffect& ranked, double) const override {
    const FemFit& f = fits_[e];
    Candidate c;
    c.effect = effects_[e].name;
    for (std::size_t p = 0; p < f.values.size(); ++p) {
      c.parameters[effects_[e].parameters[p].name] = f.values[p];
      c.parameter_std[effects_[e].parameters[p].name] = f.std[p];
    }
    c.parameters["youngs_modulus"] = f.youngs;
    c.parameter_std["youngs_modulus"] = f.youngs_std;
    c.rms = f.score.rms();
    c.force_rms = f.score.force_rms();
    c.bic = ranked.bic;
    c.explained = ranked.explained;
    return c;
  }

  void explain_named(std::size_t e, Diagnosis& out) const override {
    const FemEffect& effect = effects_[e];
    const FemFit& f = fits_[e];
    out.augmented.model = "fem";
    out.augmented.parameters = out.baseline.parameters;
    out.augmented.parameter_std = out.candidates.front().parameter_std;
    for (const auto& [key, value] : out.candidates.front().parameters) out.augmented.parameters[key] = value;
    out.augmented.rms = f.score.rms();
    out.augmented.force_rms = f.score.force_rms();
    out.improvement = 1.0 - f.score.chi() / baseline_.score.chi();
    const std::string where = where_words();
    std::ostringstream text;
    text << "The linear FEM (E " << modulus(baseline_.youngs) << ") misses "
         << (where.empty() ? std::string("the recording") : where) << " by " << size_words(out) << "; "
         << effect.physics << " explains it, cutting the held-out " << misfit_word() << " by "
         << number(100.0 * out.improvement) << " % and moving E from " << modulus(baseline_.youngs) << " to "
         << modulus(f.youngs) << ".";
    text << effect_detail(effect, f, context_);
    if (!out.runner_up.empty()) text << " " << out.runner_up << " fits almost as well; " << effect.experiment << ".";
    out.explanation = text.str();
  }

  UnexplainedWords unexplained_words(const Diagnosis& out) const override {
    UnexplainedWords w;
    w.model = "The linear FEM";
    w.where = where_words();
    w.size = size_words(out);
    w.misfit_word = misfit_word();
    w.form_hint = " (on a coarse mesh, the mesh itself)";
    return w;
  }

  void fill_evidence(bool named, std::size_t e, DiagnosisEvidence& ev) const override {
    const int frames = recording_.frame_count();
    const int n = recording_.particle_count;
    const std::vector<unsigned char>& solved = simulator_->solved();
    const FemRun& augmented = named ? fits_[e].run : baseline_.run;
    fill_recording_evidence(recording_, held_out_, ev);
    ev.simulated_baseline = fill_frames(baseline_.run.positions, recording_.frame_times_s, solved, at(n) * 3);
    ev.simulated_augmented = fill_frames(augmented.positions, recording_.frame_times_s, solved, at(n) * 3);
    ev.residual_baseline = residual_magnitudes(make_residual_field(recording_.positions, ev.simulated_baseline, n, 3));
    ev.residual_augmented =
        residual_magnitudes(make_residual_field(recording_.positions, ev.simulated_augmented, n, 3));
    if (!forces_) return;
    std::vector<unsigned char> force_known(at(frames), 0);
    for (int k : scorer_->force_frames()) force_known[at(k)] = 1;
    ev.force_observed.assign(at(frames) * 3, kNaN);
    for (int k = 0; k < frames; ++k) {
      if (simulator_->force_measured()[at(k)] == 0) continue;
      for (int d = 0; d < 3; ++d) ev.force_observed[at(k) * 3 + at(d)] = scorer_->measured_force()[at(k) * 3 + at(d)];
    }
    ev.force_baseline = fill_frames(baseline_.run.force, recording_.frame_times_s, force_known, 3);
    ev.force_augmented = fill_frames(augmented.force, recording_.frame_times_s, force_known, 3);
    for (int k = 0; k < frames; ++k) {
      if (simulator_->force_measured()[at(k)] != 0) continue;
      for (int d = 0; d < 3; ++d) {
        ev.force_baseline[at(k) * 3 + at(d)] = kNaN;
        ev.force_augmented[at(k) * 3 + at(d)] = kNaN;
      }
    }
  }

  int simulations() const override { return simulations_; }

 private:
  std::unique_ptr<FemRecordingSimulator> make_simulator(FemTimeMode mode) const {
    try {
      return std::make_unique<FemRecordingSimulator>(recording_, mode, stride_);
    } catch (const std::invalid_argument& error) {
      throw std::runtime_error(std::string("--model fem: ") + error.what());
    }
  }

  // E alone: in closed form where the run allows it, else fit_least_squares on log E.
  FemFit fit_youngs(double youngs) {
    FemFitter fitter(*simulator_, *scorer_, context_);
    const FemFitter::Evaluation ev = fitter.profile(nullptr, {}, youngs);
    if (!ev.ok) throw std::runtime_error("the FEM baseline cannot be simulated: " + ev.run.failure);
    FemFit fit;
    bool fitted = false;
    if (!fitter.profiled(nullptr)) {
      const double e0 = ev.youngs;
      const std::vector<FitParameter> parameters{{"youngs_modulus", e0, e0 / 30.0, e0 * 30.0, true}};
      const ResidualFunction function = [&](const std::vector<double>& values, std::vector<double>& residuals) {
        const FemFitter::Evaluation e = fitter.evaluate(nullptr, {}, values[0], false);
        if (!e.ok) return false;
        for (std::size_t i = 0; i < residuals.size(); ++i) residuals[i] = e.residuals(static_cast<Eigen::Index>(i));
        return true;
      };
      FitOptions fit_options;
      fit_options.loss = RobustLoss::none;
      fit_options.max_iterations = 15;
      fit_options.difference_step = 1e-3;
      try {
        const FitResult result =
            fit_least_squares(parameters, static_cast<int>(scorer_->fit_count()), function, fit_options);
        fit = fitter.finish(nullptr, {}, result.values[0], &result);
        fitted = true;
      } catch (const std::exception&) {
        // the profiled value stands
      }
    }
    if (!fitted) fit = fitter.finish(nullptr, {}, ev.youngs, nullptr);
    simulations_ += fitter.simulations;
    return fit;
  }

  std::string where_words() const {
    if (location_.particles.empty()) return "";
    std::ostringstream where;
    if (positions_) {
      where << "particles " << id_list(location_.particles);
    } else {
      where << "the force on the " << location_.particles.size() << " particles the wrench acts on";
    }
    where << " between t = " << number(location_.t_start) << " s and " << number(location_.t_end) << " s";
    return where.str();
  }

  std::string size_words(const Diagnosis& out) const {
    std::ostringstream size;
    if (forces_)
      size << number(out.baseline.force_rms) << " N rms (force noise " << number(out.force_noise_rms) << " N)";
    if (positions_) {
      if (forces_) size << " and ";
      size << number(out.baseline.rms) << " m rms (noise " << number(out.noise_rms) << " m)";
    }
    return size.str();
  }

  std::string misfit_word() const { return positions_ && forces_ ? "misfit" : (forces_ ? "force rms" : "rms"); }

  const Recording& recording_;
  const DiagnoseOptions& options_;
  double duration_ = 0;
  int stride_ = 1;
  FemTimeMode mode_ = FemTimeMode::quasi_static;
  std::unique_ptr<FemRecordingSimulator> simulator_;
  std::vector<unsigned char> held_out_;
  std::vector<unsigned char> fitting_frames_;
  double position_std_ = 0;
  double force_std_ = 0;
  std::unique_ptr<FemScorer> scorer_;
  bool positions_ = false;
  bool forces_ = false;
  FemEffectContext context_;
  FemFit baseline_;
  double lowest_period_ = kInf;
  double loading_time_ = kInf;
  Location location_;
  std::vector<FemEffect> effects_;
  std::vector<FemFit> fits_;
  int simulations_ = 0;
};

}  // namespace

DiagnoseResult diagnose_recording_fem(const Recording& recording, const DiagnoseOptions& options) {
  require_enough_frames(recording);
  if (options.fem_time != "auto" && options.fem_time != "quasi_static" && options.fem_time != "dynamic") {
    throw std::runtime_error("fem_time must be auto, quasi_static or dynamic (got '" + options.fem_time + "')");
  }
  FemDiagnosis model(recording, options);
  return run_diagnosis(model, recording.name, options);
}

}  // namespace pliant::host
