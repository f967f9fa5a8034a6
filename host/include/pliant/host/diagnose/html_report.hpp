// HTML report of `pliant diagnose REC --report DIR` (docs/spec/diagnosis-v1.md).
//
// One self-contained HTML5 page: no JavaScript, no external resources; every plot is inline SVG
// generated here, so the page works offline and can be attached to a bug report. Each plot is an
// `<svg class="plot" data-plot="NAME">` with a `<title>`; the names are
//   residual_before, residual_after       residual heat maps (particles x time), shared scale
//   trajectory_<id>                       observed / baseline / augmented, one per located particle
// and the tables carry `data-table="candidates" | "parameters" | "signatures"`.
#pragma once

#include <string>

#include "pliant/host/diagnose/diagnosis.hpp"

namespace pliant::host {

/// The report page. Never throws on odd data: zero frames or particles give a "no data" note in
/// place of the plots, NaN is shown as missing, inconsistent array sizes skip the affected plot
/// with a note, and maps larger than 200k cells are binned so the page stays a few MB.
std::string diagnosis_html(const Diagnosis& diagnosis, const DiagnosisEvidence& evidence);

/// Creates `directory` (and parents) and writes `directory/index.html` through a temporary file
/// renamed into place. Throws std::runtime_error with a one-line message on I/O failure.
void write_diagnosis_report(const Diagnosis& diagnosis, const DiagnosisEvidence& evidence,
                            const std::string& directory);

}  // namespace pliant::host
