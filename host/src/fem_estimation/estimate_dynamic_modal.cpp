// Modal warm start of estimate_dynamic.hpp: frequency matching and modal decay rates.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "pliant/host/fem/estimate_dynamic.hpp"
#include "pliant/host/fem/fem_modal.hpp"

namespace pliant::host::fem {
namespace {

std::size_t uz(int i) { return static_cast<std::size_t>(i); }
constexpr double kPi = 3.14159265358979323846;

struct SinusoidFit {
  bool ok = false;
  double frequency_hz = 0;  // damped
  double decay_1_s = 0;
  double rms = 0;     // of the signal about its mean
  double misfit = 0;  // rms residual / rms
};

// Residual of the best q(t) ~ c + exp(-s t) (a cos(w t) + b sin(w t)) for fixed w and s.
void sinusoid_residual(const std::vector<double>& t, const Eigen::VectorXd& q, double frequency_hz, double decay,
                       Eigen::VectorXd& residual) {
  const Eigen::Index n = q.size();
  Eigen::MatrixXd basis(n, 3);
  const double w = 2 * kPi * frequency_hz;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double ti = t[static_cast<std::size_t>(i)];
    const double envelope = std::exp(-decay * ti);
    basis(i, 0) = 1.0;
    basis(i, 1) = envelope * std::cos(w * ti);
    basis(i, 2) = envelope * std::sin(w * ti);
  }
  const Eigen::Vector3d c = basis.colPivHouseholderQr().solve(q);
  residual = q - basis * c;
}

// Nyquist frequency (Hz) of the median sampling interval of t (ascending, at least 2 samples).
double median_nyquist_hz(const std::vector<double>& t) {
  std::vector<double> dt;
  for (std::size_t i = 1; i < t.size(); ++i) dt.push_back(t[i] - t[i - 1]);
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
  return 0.5 / dt[dt.size() / 2];
}

// Periodogram peak, then fit_least_squares on (frequency, decay rate). t starts at 0.
SinusoidFit fit_damped_sinusoid(const std::vector<double>& t, const Eigen::VectorXd& q) {
  SinusoidFit fit;
  const Eigen::Index n = q.size();
  if (n < 6) return fit;
  const Eigen::VectorXd centred = q.array() - q.mean();
  fit.rms = std::sqrt(centred.squaredNorm() / static_cast<double>(n));
  if (!(fit.rms > 0)) return fit;
  const double span = t.back() - t.front();
  const double nyquist = median_nyquist_hz(t);

  double best_power = -1, peak = 0;
  const double df = 1.0 / (8.0 * span);
  for (double f = 0.5 / span; f <= nyquist; f += df) {
    double re = 0, im = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double phase = 2 * kPi * f * t[static_cast<std::size_t>(i)];
      re += centred(i) * std::cos(phase);
      im += centred(i) * std::sin(phase);
    }
    const double power = re * re + im * im;
    if (power > best_power) {
      best_power = power;
      peak = f;
    }
  }
  if (!(peak > 0)) return fit;

  // Envelope decay from the rms of the two halves of the record.
  const Eigen::Index half = n / 2;
  const double rms1 = std::sqrt(centred.head(half).squaredNorm() / static_cast<double>(half));
  const double rms2 = std::sqrt(centred.tail(n - half).squaredNorm() / static_cast<double>(n - half));
  const double decay_lower = 1e-4 / span, decay_upper = 2 * kPi * nyquist;
  double decay0 = rms2 > 0 && rms2 < rms1 ? 2.0 * std::log(rms1 / rms2) / span : 1e-2 / span;
  decay0 = std::clamp(decay0, decay_lower * 1.01, decay_upper / 1.01);

  std::vector<FitParameter> parameters;
  parameters.push_back({"frequency_hz", peak, std::max(peak - 1.0 / span, 0.5 * peak), peak + 1.0 / span, false});
  parameters.push_back({"decay_rate", decay0, decay_lower, decay_upper, true});
  FitOptions options;
  options.loss = RobustLoss::none;
  options.max_iterations = 100;
  options.difference_step = 1e-6;
  const ResidualFunction residuals = [&](const std::vector<double>& values, std::vector<double>& out) {
    Eigen::VectorXd r;
    sinusoid_residual(t, q, values[0], values[1], r);
    for (Eigen::Index i = 0; i < n; ++i) out[static_cast<std::size_t>(i)] = r(i);
    return true;
  };
  try {
    const FitResult result = fit_least_squares(parameters, static_cast<int>(n), residuals, options);
    Eigen::VectorXd r;
    sinusoid_residual(t, q, result.values[0], result.values[1], r);
    fit.frequency_hz = result.values[0];
    fit.decay_1_s = result.values[1];
    fit.misfit = std::sqrt(r.squaredNorm() / static_cast<double>(n)) / fit.rms;
    fit.ok = std::isfinite(fit.misfit);
  } catch (const std::exception&) {
    fit.ok = false;
  }
  return fit;
}

// Which material parameters the warm start matches (asked for and not declared known).
struct WarmStartUnknowns {
  bool modulus = false;
  bool alpha = false;
  bool beta = false;
};

WarmStartUnknowns warm_start_unknowns(const FemRecordingProblem& problem, const TrajectoryEstimateOptions& options) {
  WarmStartUnknowns u;
  u.modulus = options.estimate_youngs_modulus && !problem.is_known("youngs_modulus");
  u.alpha = options.estimate_rayleigh_alpha && !problem.is_known("rayleigh_alpha");
  u.beta = options.estimate_rayleigh_beta && !problem.is_known("rayleigh_beta");
  return u;
}

// Per node: fixed, or driven in any frame (held still for the modal analysis).
std::vector<bool> constrained_nodes(const FemRecordingProblem& problem) {
  std::vector<bool> constrained(uz(problem.mesh.point_count()), false);
  for (int node : problem.fixed_nodes) constrained[uz(node)] = true;
  for (const FemFrame& frame : problem.frames) {
    for (int node : frame.driven_nodes) constrained[uz(node)] = true;
  }
  return constrained;
}

// The warm start before any matching: the reference modulus (initial, or the problem's when it is
// not estimated) and the initial or known Rayleigh coefficients.
ModalWarmStart unmatched_warm_start(const FemRecordingProblem& problem, const TrajectoryEstimateOptions& options,
                                    const WarmStartUnknowns& unknowns) {
  ModalWarmStart warm;
  warm.reference_youngs_modulus_pa =
      options.initial_youngs_modulus_pa > 0 ? options.initial_youngs_modulus_pa : problem.material.youngs_modulus_pa;
  if (!unknowns.modulus) warm.reference_youngs_modulus_pa = problem.material.youngs_modulus_pa;
  warm.youngs_modulus_pa = warm.reference_youngs_modulus_pa;
  warm.rayleigh_alpha = unknowns.alpha ? options.initial_rayleigh_alpha : problem.material.rayleigh_alpha;
  warm.rayleigh_beta = unknowns.beta ? options.initial_rayleigh_beta : problem.material.rayleigh_beta;
  return warm;
}

// The lowest min(warm_start_modes, free dofs - 1) modes with the constrained nodes clamped.
FemModes lowest_modes(const FemModel& model, const std::vector<bool>& constrained, int warm_start_modes,
                      const std::string& label) {
  std::vector<int> held;
  const int n = static_cast<int>(constrained.size());
  for (int node = 0; node < n; ++node) {
    if (constrained[uz(node)]) held.push_back(node);
  }
  const int free_dofs = 3 * (n - static_cast<int>(held.size()));
  FemModalOptions modal_options;
  modal_options.mode_count = std::min(warm_start_modes, free_dofs - 1);
  if (modal_options.mode_count < 1) throw std::invalid_argument(label + "too few free nodes");
  return modal_analysis(model, held, modal_options);
}

// Modal coordinates (m sqrt(kg)) of the frames that observe enough free nodes (3 x nodes >= 2 x
// modes), with their times (s, from the recording).
struct ModalSeries {
  std::vector<double> times;
  std::vector<Eigen::VectorXd> coordinates;  // mode_count each
};

// Mass-weighted least squares of each frame's observed free displacements on the mode shapes; the
// normal matrix is refactored only when the observed set changes.
ModalSeries modal_coordinates(const FemRecordingProblem& problem, const FemModel& model, const FemModes& modes,
                              const std::vector<bool>& constrained, int mode_count) {
  const Eigen::VectorXd& mass = model.lumped_mass_kg();
  const Eigen::VectorXd& rest = model.rest_position_m();
  ModalSeries series;
  std::vector<int> pattern;
  Eigen::LDLT<Eigen::MatrixXd> normal;
  for (const FemFrame& frame : problem.frames) {
    std::vector<int> nodes;
    for (int node : frame.observed_nodes) {
      if (!constrained[uz(node)]) nodes.push_back(node);
    }
    if (3 * static_cast<int>(nodes.size()) < 2 * mode_count) continue;
    if (nodes != pattern || series.coordinates.empty()) {
      Eigen::MatrixXd a = Eigen::MatrixXd::Zero(mode_count, mode_count);
      for (int node : nodes) {
        const auto phi = modes.shape.middleRows(3 * static_cast<Eigen::Index>(node), 3);
        a.noalias() += mass[node] * phi.transpose() * phi;
      }
      normal.compute(a);
      pattern = nodes;
    }
    Eigen::VectorXd b = Eigen::VectorXd::Zero(mode_count);
    for (int node : nodes) {
      const auto phi = modes.shape.middleRows(3 * static_cast<Eigen::Index>(node), 3);
      const Eigen::Vector3d u = frame.observed_position_m.segment<3>(3 * node) - rest.segment<3>(3 * node);
      b.noalias() += mass[node] * phi.transpose() * u;
    }
    series.times.push_back(frame.time_s);
    series.coordinates.push_back(normal.solve(b));
  }
  return series;
}

// One damped sinusoid per modal coordinate (times taken from the first sample).
std::vector<SinusoidFit> fit_modal_sinusoids(const ModalSeries& series, int mode_count) {
  const Eigen::Index samples = static_cast<Eigen::Index>(series.coordinates.size());
  std::vector<SinusoidFit> fits;
  for (int k = 0; k < mode_count; ++k) {
    Eigen::VectorXd q(samples);
    for (Eigen::Index i = 0; i < samples; ++i) q(i) = series.coordinates[static_cast<std::size_t>(i)](k);
    fits.push_back(fit_damped_sinusoid(series.times, q));
  }
  return fits;
}

// The largest rms among the successful fits (0 for none).
double largest_fitted_rms(const std::vector<SinusoidFit>& fits) {
  double largest = 0;
  for (const SinusoidFit& fit : fits) {
    if (fit.ok) largest = std::max(largest, fit.rms);
  }
  return largest;
}

// Each mode's measurement, and which to trust (provisionally used_for_damping): a clean damped
// sinusoid (misfit < 0.2), not negligible (rms at least 1e-3 of the largest) and below 0.8
// Nyquist. Returns the trusted mode of largest rms (-1: none).
int measure_modes(const FemModes& modes, const std::vector<SinusoidFit>& fits, double largest, double nyquist,
                  std::vector<ModeMeasurement>& measured) {
  int dominant = -1;
  for (int k = 0; k < static_cast<int>(fits.size()); ++k) {
    const SinusoidFit& fit = fits[uz(k)];
    ModeMeasurement mode;
    mode.mode = k;
    mode.model_frequency_hz = modes.frequency_hz(k);
    mode.rms_amplitude = fit.rms;
    mode.relative_misfit = fit.ok ? fit.misfit : 1.0;
    if (fit.ok) {
      const double wd = 2 * kPi * fit.frequency_hz;
      mode.observed_frequency_hz = std::sqrt(wd * wd + fit.decay_1_s * fit.decay_1_s) / (2 * kPi);
      mode.decay_rate_1_s = fit.decay_1_s;
    }
    measured.push_back(mode);
    const bool clean = fit.ok && fit.misfit < 0.2 && fit.rms >= 1e-3 * largest &&
                       mode.observed_frequency_hz < 0.8 * nyquist && mode.model_frequency_hz > 0;
    if (clean && (dominant < 0 || fit.rms > fits[uz(dominant)].rms)) dominant = k;
    measured.back().used_for_damping = clean;  // provisional
  }
  return dominant;
}

// Untrusts the modes whose frequency ratio to the model is over 25 % off the dominant mode's
// (rejects coordinates driven by another mode's harmonics, e.g. the axial motion at twice the
// bending frequency of a large swing). With fit_modulus, E = E0 (f_obs / f_model)^2, log-averaged
// with weights rms^2 over the remaining trusted modes.
void match_modulus(bool fit_modulus, int dominant, ModalWarmStart& warm) {
  double log_sum = 0, weight_sum = 0;
  for (ModeMeasurement& mode : warm.modes) {
    if (!mode.used_for_damping || dominant < 0) continue;
    const ModeMeasurement& d = warm.modes[uz(dominant)];
    const double ratio = mode.observed_frequency_hz / mode.model_frequency_hz;
    const double dominant_ratio = d.observed_frequency_hz / d.model_frequency_hz;
    if (std::abs(std::log(ratio / dominant_ratio)) > std::log(1.25)) {
      mode.used_for_damping = false;
      continue;
    }
    if (fit_modulus) {
      const double w = mode.rms_amplitude * mode.rms_amplitude;
      log_sum += w * 2.0 * std::log(ratio);
      weight_sum += w;
      mode.used_for_modulus = true;
    }
  }
  if (weight_sum > 0) {
    warm.modulus_matched = true;
    warm.youngs_modulus_pa = warm.reference_youngs_modulus_pa * std::exp(log_sum / weight_sum);
  }
}

// Decay rates of the trusted modes: omega (rad/s), sigma (1/s) and the relative weight of each,
// sqrt(its amplitude share) / sigma.
struct ModalDecays {
  std::vector<double> omega;
  std::vector<double> sigma;
  std::vector<double> weight;
};

ModalDecays trusted_decays(const std::vector<ModeMeasurement>& modes, double largest) {
  ModalDecays d;
  for (const ModeMeasurement& mode : modes) {
    if (!mode.used_for_damping || !(mode.decay_rate_1_s > 0)) continue;
    d.omega.push_back(2 * kPi * mode.observed_frequency_hz);
    d.sigma.push_back(mode.decay_rate_1_s);
    d.weight.push_back(std::sqrt(mode.rms_amplitude / largest) / mode.decay_rate_1_s);
  }
  return d;
}

// Weighted least squares of sigma = alpha / 2 + beta omega^2 / 2 for the coefficients marked
// with_*; the others are held at their current value.
void solve_rayleigh(const ModalDecays& d, bool with_alpha, bool with_beta, double& alpha, double& beta) {
  const int cols = (with_alpha ? 1 : 0) + (with_beta ? 1 : 0);
  Eigen::MatrixXd a(static_cast<Eigen::Index>(d.omega.size()), cols);
  Eigen::VectorXd b(static_cast<Eigen::Index>(d.omega.size()));
  for (std::size_t i = 0; i < d.omega.size(); ++i) {
    const Eigen::Index r = static_cast<Eigen::Index>(i);
    double rhs = d.sigma[i];
    int c = 0;
    if (with_alpha)
      a(r, c++) = 0.5 * d.weight[i];
    else
      rhs -= 0.5 * alpha;
    if (with_beta)
      a(r, c) = 0.5 * d.omega[i] * d.omega[i] * d.weight[i];
    else
      rhs -= 0.5 * beta * d.omega[i] * d.omega[i];
    b(r) = rhs * d.weight[i];
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  int c = 0;
  if (with_alpha) alpha = x(c++);
  if (with_beta) beta = x(c);
}

// Rayleigh coefficients from the trusted modes' decay rates, non-negative with small floors (2 %
// of the lowest mode's sigma for alpha, of the highest's sigma / omega^2 for beta) so a log-scale
// fit can still move them. One distinct frequency cannot separate the two: alpha goes to its floor.
// Unchanged when no trusted mode decays or neither coefficient is estimated.
void match_damping(const FemRecordingProblem& problem, const TrajectoryEstimateOptions& options,
                   const WarmStartUnknowns& unknowns, double largest, ModalWarmStart& warm) {
  const ModalDecays d = trusted_decays(warm.modes, largest);
  if (d.omega.empty() || !(unknowns.alpha || unknowns.beta)) return;
  const double omega_min = *std::min_element(d.omega.begin(), d.omega.end());
  const double omega_max = *std::max_element(d.omega.begin(), d.omega.end());
  const bool distinct = omega_max > 1.2 * omega_min;
  const std::size_t lowest = uz(static_cast<int>(std::min_element(d.omega.begin(), d.omega.end()) - d.omega.begin()));
  const std::size_t highest = uz(static_cast<int>(std::max_element(d.omega.begin(), d.omega.end()) - d.omega.begin()));
  const double alpha_floor = 0.02 * d.sigma[lowest];
  const double beta_floor = 0.02 * d.sigma[highest] / (d.omega[highest] * d.omega[highest]);
  const double known_alpha = problem.material.rayleigh_alpha;
  const double known_beta = problem.material.rayleigh_beta;
  double alpha = unknowns.alpha ? 0.0 : known_alpha;
  double beta = unknowns.beta ? 0.0 : known_beta;
  if (unknowns.alpha && unknowns.beta && distinct) {
    solve_rayleigh(d, true, true, alpha, beta);
    if (alpha < alpha_floor) {
      alpha = alpha_floor;
      solve_rayleigh(d, false, true, alpha, beta);
    } else if (beta < beta_floor) {
      beta = beta_floor;
      solve_rayleigh(d, true, false, alpha, beta);
    }
  } else if (unknowns.alpha && unknowns.beta) {
    alpha = alpha_floor;  // one frequency cannot separate the two: the decay goes to beta
    solve_rayleigh(d, false, true, alpha, beta);
  } else {
    solve_rayleigh(d, unknowns.alpha, unknowns.beta, alpha, beta);
  }
  warm.rayleigh_alpha = unknowns.alpha ? std::max(alpha, alpha_floor) : known_alpha;
  warm.rayleigh_beta = unknowns.beta ? std::max(beta, beta_floor) : known_beta;
  warm.damping_matched = std::isfinite(warm.rayleigh_alpha) && std::isfinite(warm.rayleigh_beta);
  if (!warm.damping_matched) {
    warm.rayleigh_alpha = unknowns.alpha ? options.initial_rayleigh_alpha : known_alpha;
    warm.rayleigh_beta = unknowns.beta ? options.initial_rayleigh_beta : known_beta;
  }
}

// Frequencies and decay rates of the modal coordinates (at least 6 samples, times from 0), then
// the modulus and damping matched to them.
void match_modal_series(const FemRecordingProblem& problem, const TrajectoryEstimateOptions& options,
                        const WarmStartUnknowns& unknowns, const FemModes& modes, int mode_count, ModalSeries series,
                        ModalWarmStart& warm) {
  const double t0 = series.times.front();
  for (double& t : series.times) t -= t0;
  const std::vector<SinusoidFit> fits = fit_modal_sinusoids(series, mode_count);
  const double largest = largest_fitted_rms(fits);
  const int dominant = measure_modes(modes, fits, largest, median_nyquist_hz(series.times), warm.modes);
  match_modulus(unknowns.modulus, dominant, warm);
  match_damping(problem, options, unknowns, largest, warm);
}

}  // namespace

ModalWarmStart modal_warm_start(const FemRecordingProblem& problem, const TrajectoryEstimateOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  const std::string label = "modal warm start (" + problem.name + "): ";
  if (problem.frames.size() < 3) throw std::invalid_argument(label + "at least 3 frames are needed");
  if (options.warm_start_modes < 1) throw std::invalid_argument(label + "warm_start_modes must be >= 1");
  const WarmStartUnknowns unknowns = warm_start_unknowns(problem, options);
  const std::vector<bool> constrained = constrained_nodes(problem);
  ModalWarmStart warm = unmatched_warm_start(problem, options, unknowns);

  FemModel model(problem.mesh, problem.material);
  if (unknowns.modulus) model.set_youngs_modulus(warm.reference_youngs_modulus_pa);
  const FemModes modes = lowest_modes(model, constrained, options.warm_start_modes, label);
  const int mode_count = static_cast<int>(modes.frequency_hz.size());
  ModalSeries series = modal_coordinates(problem, model, modes, constrained, mode_count);
  // Fewer than 6 samples cannot fix a damped sinusoid: the warm start stays unmatched.
  if (series.coordinates.size() >= 6) {
    match_modal_series(problem, options, unknowns, modes, mode_count, std::move(series), warm);
  }
  warm.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return warm;
}

}  // namespace pliant::host::fem
