// The human-readable report of `pliant estimate`: what a robotics engineer checks first.
#pragma once

#include <string>
#include <vector>

#include "pliant/host/estimate.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::cli {

/// Doubts about the estimate worth a warning line (ambiguous minimum, unidentifiable beta,
/// unconverged relaxations, ...); empty when the estimate is clean.
std::vector<std::string> estimate_warnings(const host::EstimateReport& report);

/// Multi-line summary: recording, mode, parameters with uncertainty, fit quality, model
/// choices, runtime, warnings and a text plot of the error curve. Ends with a newline.
std::string format_estimate_summary(const host::Recording& recording, const host::EstimateOptions& options,
                                    const host::EstimateReport& report);

/// Text plot of E(msm_beta): about `rows` samples spread over [0, 1] plus the one nearest the
/// estimate, one row each ("beta  error  bar"), the estimate's row marked.
std::string format_error_curve(const host::EstimateReport& report, const std::string& unit, int rows);

}  // namespace pliant::cli
