// The diagnosis pipeline, written once. A model -- the MSM
// (diagnose.cpp) or the FEM (fem_diagnose.cpp) -- is an adapter that fits its baseline and every
// catalogued effect, scores them on held-out frames and words what it found; run_diagnosis
// takes the steps in order (docs/diagnose.md):
//
//   1. baseline   DiagnosisModel::fit_baseline      the model without added physics
//   2. locate     DiagnosisModel::locate            where and when the baseline misses
//   3. fit        DiagnosisModel::catalogue         the effects that apply to this recording,
//                 DiagnosisModel::fit_effects       each fitted with the baseline's parameters
//   4. select     select_effect (selection.hpp)     on each fit's FitEvidence
//   5. explain    candidates, verdict, explanation, evidence for the report
//
// An adapter is made for one recording and used once; run_diagnosis calls its methods in the
// order above, each once, from the calling thread (fit_effects may use worker threads inside).
// A new model becomes diagnosable by writing an adapter. Host code: allocates; the adapters
// throw std::runtime_error with one line when the recording cannot be diagnosed.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "pliant/host/diagnose/diagnose.hpp"
#include "pliant/host/diagnose/diagnosis.hpp"
#include "pliant/host/diagnose/selection.hpp"

namespace pliant::host {

/// The words of an explanation when no effect is named.
struct UnexplainedWords {
  std::string model;        ///< "The elastic model", "The linear FEM"
  std::string where;        ///< "particles 3-7 between t = ...", "" when not located
  std::string size;         ///< the baseline's held-out misfit with its unit and noise
  std::string misfit_word;  ///< "rms", "force rms", "misfit"
  std::string form_hint;    ///< added to "the model's form is off" ("" or " (...)")
};

class DiagnosisModel {
 public:
  virtual ~DiagnosisModel() = default;

  /// 1. Fits the baseline on the fitting frames; fills out.baseline and the noise fields.
  virtual void fit_baseline(Diagnosis& out) = 0;
  /// 2. Locates the baseline's misfit (out.location); returns its signature statistics.
  virtual std::map<std::string, double> locate(Diagnosis& out) = 0;
  /// 3. The effects that apply to this recording (names, in catalogue order) ...
  virtual std::vector<std::string> catalogue() = 0;
  /// ... each fitted; `one_done` is called after each (from the calling thread).
  virtual void fit_effects(int threads, const std::function<void()>& one_done) = 0;

  /// 4. What selection sees of the baseline and of each effect's fit, in one misfit unit.
  virtual FitEvidence baseline_evidence() const = 0;
  virtual FitEvidence effect_evidence(std::size_t effect) const = 0;
  virtual double noise_misfit() const = 0;
  /// Cluster of every fitting residual (selection.hpp); empty: independent residuals.
  virtual std::vector<int> residual_clusters() const = 0;

  /// 5. The JSON candidate of a fitted effect, its std widened by sqrt(design_effect).
  virtual Candidate candidate(std::size_t effect, const RankedEffect& ranked, double design_effect) const = 0;
  /// The named effect: fills out.augmented, out.improvement and out.explanation (out.candidates
  /// and out.runner_up are already filled).
  virtual void explain_named(std::size_t effect, Diagnosis& out) const = 0;
  virtual UnexplainedWords unexplained_words(const Diagnosis& out) const = 0;
  /// Simulated tracks (and forces) of the baseline and of the named effect (`named` false:
  /// the baseline's twice) and the recording's own data for the report.
  virtual void fill_evidence(bool named, std::size_t effect, DiagnosisEvidence& evidence) const = 0;
  /// Simulations run so far.
  virtual int simulations() const = 0;
};

/// Runs the pipeline on one adapter. `recording_name` goes into the document.
DiagnoseResult run_diagnosis(DiagnosisModel& model, const std::string& recording_name, const DiagnoseOptions& options);

/// Throws std::runtime_error when the recording has too few frames to hold any out (10).
void require_enough_frames(const Recording& recording);

/// Held-out block length in frames: `requested` when > 0, else about a tenth of a second at the
/// recording's frame rate, at most frames / max_share_divisor, at least 3.
int holdout_block_frames(const Recording& recording, int requested, int max_share_divisor);

/// The recording's own part of the report evidence: frames, observed tracks, held-out mask,
/// fixed and driven ids (sorted, unique).
void fill_recording_evidence(const Recording& recording, const std::vector<unsigned char>& held_out,
                             DiagnosisEvidence& evidence);

}  // namespace pliant::host
