#include "pliant/host/diagnose/engine.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "words.hpp"

namespace pliant::host {
namespace {

// 4. Every fit as selection sees it, and the decision.
Selection select(const DiagnosisModel& model, const std::vector<std::string>& names,
                 const std::vector<int>& residual_clusters, const SelectionRules& rules) {
  std::vector<FitEvidence> effects;
  for (std::size_t e = 0; e < names.size(); ++e) effects.push_back(model.effect_evidence(e));
  return select_effect(model.baseline_evidence(), effects, model.noise_misfit(), residual_clusters, rules);
}

// 5. The verdict when nothing is named: `unknown` for a large located misfit, else
// `consistent`, with the near miss and why it was not named.
void explain_unexplained(const DiagnosisModel& model, const Selection& selection, const std::vector<std::string>& names,
                         const SelectionRules& rules, Diagnosis& out) {
  out.augmented = out.baseline;
  out.improvement = 0;
  const UnexplainedWords words = model.unexplained_words(out);
  const std::string near_miss = not_named_sentence(selection, names, words.misfit_word, words.form_hint, rules);
  if (unexplained_misfit_is_unknown(selection, !out.location.particles.empty(), rules)) {
    out.verdict = "missing_physics";
    out.effect = "unknown";
    out.explanation = words.model + " misses " + words.where + " by " + words.size + ", " +
                      words::number(selection.misfit) +
                      " times the noise, and no catalogued effect explains it clearly." + near_miss;
  } else {
    out.verdict = "consistent";
    out.effect = "none";
    out.explanation = words.model + " explains the recording to within " + words::number(selection.misfit) +
                      " times the measurement noise on held-out frames; no added physics improves it clearly." +
                      near_miss;
  }
}

}  // namespace

DiagnoseResult run_diagnosis(DiagnosisModel& model, const std::string& recording_name, const DiagnoseOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  auto report = [&](const std::string& stage, int done, int total) {
    if (options.progress) options.progress(stage, done, total);
  };
  DiagnoseResult result;
  Diagnosis& out = result.diagnosis;
  out.recording = recording_name;

  report("baseline", 0, 1);
  model.fit_baseline(out);
  report("baseline", 1, 1);

  const std::map<std::string, double> signatures = model.locate(out);

  const std::vector<std::string> names = model.catalogue();
  const int total = static_cast<int>(names.size());
  int done = 0;
  report("effects", 0, total);
  model.fit_effects(options.threads, [&]() { report("effects", ++done, total); });

  const SelectionRules rules;
  const std::vector<int> clusters = model.residual_clusters();
  const Selection selection = select(model, names, clusters, rules);
  for (const RankedEffect& r : selection.ranked) {
    out.candidates.push_back(model.candidate(r.effect, r, selection.design_effect));
  }
  if (!selection.ranked.empty() && selection.ranked.front().passes) out.selection_stability = selection.stability;
  if (selection.has_runner_up) out.runner_up = names[selection.runner_up];

  const std::size_t named = selection.named ? selection.ranked.front().effect : 0;
  if (selection.named) {
    out.verdict = "missing_physics";
    out.effect = names[named];
    model.explain_named(named, out);
  } else {
    explain_unexplained(model, selection, names, rules, out);
  }

  DiagnosisEvidence& evidence = result.evidence;
  model.fill_evidence(selection.named, named, evidence);
  evidence.signatures = signatures;
  evidence.signatures["misfit_over_noise"] = selection.misfit;
  evidence.signatures["simulations"] = model.simulations();
  if (!clusters.empty()) evidence.signatures["design_effect"] = selection.design_effect;
  result.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

void require_enough_frames(const Recording& recording) {
  constexpr int kMinFrames = 10;
  if (recording.frame_count() < kMinFrames) {
    throw std::runtime_error("too few frames (" + std::to_string(recording.frame_count()) +
                             "); diagnose needs at least " + std::to_string(kMinFrames));
  }
}

int holdout_block_frames(const Recording& recording, int requested, int max_share_divisor) {
  if (requested > 0) return requested;
  const int frames = recording.frame_count();
  const double duration = recording.frame_times_s.back() - recording.frame_times_s.front();
  const double rate = duration > 0 ? (frames - 1) / duration : 30.0;
  const int cap = frames / std::max(max_share_divisor, 1);
  return std::max(3, std::min(static_cast<int>(std::lround(0.1 * rate)), cap));
}

void fill_recording_evidence(const Recording& recording, const std::vector<unsigned char>& held_out,
                             DiagnosisEvidence& evidence) {
  evidence.dimension = recording.dimension;
  evidence.particle_count = recording.particle_count;
  evidence.length_unit = recording.length_unit;
  evidence.frame_times_s = recording.frame_times_s;
  evidence.held_out = held_out;
  evidence.observed = recording.positions;
  evidence.fixed = recording.fixed;
  evidence.driven.clear();
  for (const DrivenWindow& w : recording.driven) evidence.driven.push_back(w.id);
  std::sort(evidence.driven.begin(), evidence.driven.end());
  evidence.driven.erase(std::unique(evidence.driven.begin(), evidence.driven.end()), evidence.driven.end());
}

}  // namespace pliant::host
