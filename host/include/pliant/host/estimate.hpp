// msm_beta estimation of a whole recording (host side of `pliant estimate`).
//
// Builds the MSM model from the recording (msm_setup.hpp), runs the core estimator in double
// precision and returns the result with its error curve. estimate_json() renders the
// `pliant-estimate` v1 document (docs/spec/outputs-v1.md). Host code: allocates, throws
// std::runtime_error with a one-line message when the recording cannot be estimated.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pliant/core/deformability.hpp"
#include "pliant/host/msm_setup.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

struct EstimateOptions {
  FitMode mode = FitMode::trajectory;
  bool estimate_alpha = false;
  double msm_alpha = 1.0;  ///< used when msm_alpha is not estimated
  int grid_points = 11;
  double tolerance = 1e-3;
  MsmSetupOptions setup;
  /// Refits with the rest shape and the tool track perturbed by the measured position noise,
  /// this many times; their spread is the part of the uncertainty that input noise causes
  /// (the curvature of the error curve only sees noise on the compared particles). 0: off.
  int input_noise_samples = 8;
  ProgressCallback progress = nullptr;  ///< forwarded to DeformabilityConfig; must not block
  void* progress_context = nullptr;
};

struct EstimateReport {
  DeformabilityResult result;
  std::vector<double> curve_beta;
  std::vector<double> curve_error;
  int cluster_count = 0;
  int rest_frames = 1;                ///< leading still frames averaged into the rest shape
  double noise_std = 0;               ///< position noise used for the input perturbation
  double msm_beta_std_curvature = 0;  ///< from the error curve alone (core estimator)
  double msm_beta_std_input = 0;      ///< spread of refits under perturbed inputs
  double msm_beta_std = 0;            ///< combined: sqrt(curvature^2 + input^2)
  double spacing = 0;                 ///< median nearest-neighbour distance of the rest shape
  double frame_interval_s = 0;        ///< mean time step used by the simulation
  double runtime_s = 0;
};

/// Throws std::runtime_error naming the problem (e.g. "every particle is fixed or driven").
EstimateReport estimate_recording(const Recording& recording, const EstimateOptions& options);

/// The outputs-v1 `pliant-estimate` document for a report.
nlohmann::json estimate_json(const Recording& recording, const EstimateOptions& options, const EstimateReport& report);

/// "final" / "trajectory" and back; parse throws std::invalid_argument on anything else.
const char* fit_mode_name(FitMode mode);
FitMode parse_fit_mode(const std::string& name);

}  // namespace pliant::host
