#include "estimate_summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>

namespace pliant::cli {
namespace {

std::string format(const char* pattern, ...) __attribute__((format(printf, 1, 2)));

std::string format(const char* pattern, ...) {
  va_list args;
  va_start(args, pattern);
  va_list measure;
  va_copy(measure, args);
  const int length = std::vsnprintf(nullptr, 0, pattern, measure);
  va_end(measure);
  std::string text(static_cast<std::size_t>(std::max(length, 0)) + 1, '\0');
  std::vsnprintf(text.data(), text.size(), pattern, args);
  va_end(args);
  text.pop_back();  // the terminating NUL
  return text;
}

std::string uncertainty_text(double std_dev) {
  if (!std::isfinite(std_dev)) return "± ? (not identifiable)";
  return format("± %.2g", std_dev);
}

// Indices of the curve samples nearest to `rows` evenly spaced beta values, without repeats.
std::vector<std::size_t> plot_rows(const std::vector<double>& beta, int rows) {
  std::vector<std::size_t> picked;
  if (beta.empty()) return picked;
  const double lo = beta.front();
  const double hi = beta.back();
  for (int r = 0; r < rows; ++r) {
    const double target = rows > 1 ? lo + (hi - lo) * r / (rows - 1) : lo;
    std::size_t best = 0;
    for (std::size_t i = 1; i < beta.size(); ++i) {
      if (std::abs(beta[i] - target) < std::abs(beta[best] - target)) best = i;
    }
    if (picked.empty() || picked.back() != best) picked.push_back(best);
  }
  return picked;
}

}  // namespace

std::vector<std::string> estimate_warnings(const host::EstimateReport& report) {
  const DeformabilityResult& r = report.result;
  std::vector<std::string> warnings;
  if (!std::isfinite(report.msm_beta_std)) {
    warnings.emplace_back("msm_beta is not identifiable from this recording (the error curve is flat at the minimum)");
  } else if (!r.unique_minimum) {
    warnings.emplace_back("the error curve has no unique minimum; msm_beta may be ambiguous (see the curve)");
  }
  if (r.unconverged_equilibria > 0) {
    warnings.push_back(std::to_string(r.unconverged_equilibria) +
                       " equilibrium relaxations hit their iteration bound; the final-mode error is approximate");
  }
  if (r.frames_without_observations > 0) {
    warnings.push_back(std::to_string(r.frames_without_observations) +
                       " frames observe no free particle and carry no information");
  }
  return warnings;
}

std::string format_error_curve(const host::EstimateReport& report, const std::string& unit, int rows) {
  const std::vector<double>& beta = report.curve_beta;
  const std::vector<double>& error = report.curve_error;
  if (beta.empty() || beta.size() != error.size()) return "";
  std::vector<std::size_t> picked = plot_rows(beta, rows);
  std::size_t nearest = 0;
  for (std::size_t i = 1; i < beta.size(); ++i) {
    if (std::abs(beta[i] - report.result.msm_beta) < std::abs(beta[nearest] - report.result.msm_beta)) nearest = i;
  }
  // A row that would print the same beta as the estimate's shows the estimate's sample instead.
  for (std::size_t& i : picked) {
    if (std::abs(beta[i] - beta[nearest]) < 5e-4) i = nearest;
  }
  picked.push_back(nearest);
  std::sort(picked.begin(), picked.end());
  picked.erase(std::unique(picked.begin(), picked.end()), picked.end());

  double lowest = error[picked.front()];
  double highest = lowest;
  for (std::size_t i : picked) {
    lowest = std::min(lowest, error[i]);
    highest = std::max(highest, error[i]);
  }
  // Bars span the plotted range, not zero to max: the basin near the minimum is what matters,
  // and the far end of the curve would otherwise flatten it. The header states the range.
  constexpr int bar_cells = 40;
  std::string text = format("error curve (mean distance, %s; bars span %.3g to %.3g)\n  beta   error\n", unit.c_str(),
                            lowest, highest);
  for (std::size_t i : picked) {
    const double share = highest > lowest && std::isfinite(error[i]) ? (error[i] - lowest) / (highest - lowest) : 0.0;
    const int cells = 1 + static_cast<int>(std::lround(share * (bar_cells - 1)));
    std::string bar(static_cast<std::size_t>(cells), '#');
    if (i == nearest) bar += "  <- estimate";
    text += format("  %.3f  %-9.3g  ", beta[i], error[i]) + bar + "\n";
  }
  return text;
}

std::string format_estimate_summary(const host::Recording& recording, const host::EstimateOptions& options,
                                    const host::EstimateReport& report) {
  const DeformabilityResult& r = report.result;
  const std::string& unit = recording.length_unit;
  std::string text;
  text += format("recording   %s: %d particles, %d frames, %dD, %s\n", recording.name.c_str(), recording.particle_count,
                 recording.frame_count(), recording.dimension, unit.c_str());
  text += format("mode        %s\n", host::fit_mode_name(options.mode));
  text += format("msm_beta    %.3f ", r.msm_beta) + uncertainty_text(report.msm_beta_std) + "\n";
  if (std::isfinite(report.msm_beta_std)) {
    text += format(
        "            (1 sd: %.2g from the error curve, %.2g from input noise of %.3g %s, %.2g from the "
        "model's form)\n",
        report.msm_beta_std_curvature, report.msm_beta_std_input, report.noise_std, unit.c_str(),
        report.msm_beta_std_model_form);
  }
  text += format("msm_alpha   %.3f (%s)\n", r.msm_alpha, report.baseline.alpha_fitted() ? "fitted" : "held");
  text += "baseline    " + report.baseline.reason + "\n";
  text += format("unique min  %s\n", r.unique_minimum ? "yes" : "no");
  text += format("rms         %.3g %s (mean error %.3g %s over %ld residuals)\n", r.rms, unit.c_str(), r.error,
                 unit.c_str(), r.residual_count);
  const int steps = report.baseline.steps_per_frame();
  text += format(
      "model       %d clusters of radius %.3g, time step %.4g s, %d step%s per frame, rest from %d still frame%s\n",
      report.cluster_count, report.cluster_radius_factor, report.frame_interval_s / steps, steps, steps == 1 ? "" : "s",
      report.rest_frames, report.rest_frames == 1 ? "" : "s");
  text += format("runtime     %.2f s (%d error evaluations)\n", report.runtime_s, r.evaluations);
  for (const std::string& warning : estimate_warnings(report)) text += "warning: " + warning + "\n";
  text += "\n" + format_error_curve(report, unit, 11);
  return text;
}

}  // namespace pliant::cli
