// The model-independent half of `pliant diagnose`: which effect, if any, is named. The MSM
// (diagnose.cpp) and the FEM (fem_diagnose.cpp) are adapters: each fits its baseline and every
// catalogued effect, reduces each fit to a FitEvidence, and hands them here. The rules are those
// of docs/spec/diagnosis-v1.md and docs/diagnose.md (steps 5 and 6):
//
// - An effect passes when the baseline misfit stands clearly above the noise (held-out misfit
//   / noise >= min_misfit), its held-out misfit improves by >= min_improvement, its BIC beats the
//   baseline's by >= min_bic_gain, one of its parameters is >= min_significance standard
//   deviations from its null, and it explains >= min_explained_share of the misfit beyond the
//   noise.
// - Residuals are correlated within a cluster (a particle's track over the recording): every BIC
//   counts them as worth n / deff independent samples and every std is widened by sqrt(deff),
//   deff the design effect (Kish) of the best-fitting model's residuals.
// - The passing effect with the lowest held-out misfit is named only when it still improves by
//   min_improvement in >= stable_share of block-bootstrap resamples of the held-out frames. A
//   passing rival that wins >= rival_share of the resamples, or whose BIC is within close_bic,
//   is reported as the runner-up.
//
// Units: the held-out misfit, the fitting residuals and noise_misfit share one unit (the MSM's
// lengths, or the FEM's whitened residuals with noise 1). Host code: allocates; throws
// std::invalid_argument when the evidence is inconsistent (block counts differ between fits,
// sizes of values, std and nulls differ, a cluster list does not match the residuals).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Dense>

namespace pliant::host {

/// Held-out squared residual sum and its count of residuals (MSM: Euclidean pairs; FEM: whitened
/// scalars) over one block of consecutive held-out frames.
struct HeldBlock {
  double rss = 0;
  long count = 0;
};

/// The held-out block (0, 1, ...) of every frame, -1 for fitting frames; `held_out` as
/// interleaved_holdout gives it. `block_count` receives the number of blocks.
std::vector<int> held_block_of_frame(const std::vector<unsigned char>& held_out, int& block_count);

/// One fit as selection sees it: the baseline, or the baseline with one effect.
struct FitEvidence {
  bool ok = true;  ///< false: the fit could not be simulated; it is never named
  /// Residual scalars on the fitting frames, in one fixed order for every fit.
  Eigen::VectorXd fit_residuals;
  int fitted = 0;                      ///< coordinates the fit moved (the BIC's parameter count)
  std::vector<HeldBlock> held_blocks;  ///< per held-out block, in frame order
  std::vector<double> values;          ///< the effect's parameters, physical units
  std::vector<double> std;             ///< one each, before the design effect; inf: not identified
  std::vector<double> nulls;           ///< each parameter's "no effect" value; NaN: not tested
  double held_misfit() const;          ///< sqrt(sum rss / sum count) over the held-out blocks
};

struct SelectionRules {
  double min_misfit = 1.5;        ///< baseline held-out misfit / noise worth explaining
  double unknown_misfit = 5.0;    ///< unexplained misfit / noise reported as `unknown`
  double min_improvement = 0.3;   ///< held-out misfit must fall by this share ...
  double min_bic_gain = 10.0;     ///< ... with "very strong" evidence (Kass and Raftery 1995) ...
  double min_significance = 3.0;  ///< ... and a parameter this many std from its null
  double min_explained = 0.75;    ///< share of the misfit beyond the noise explained
  int bootstrap_resamples = 400;
  double stable_share = 0.8;  ///< the named effect holds in this share of resamples
  double rival_share = 0.2;   ///< a rival winning this share of them is reported
  double close_bic = 6.0;     ///< a passing rival this close in BIC is reported
};

/// One effect's standing.
struct RankedEffect {
  std::size_t effect = 0;  ///< index into the effects handed to select_effect
  double significance = 0;
  double improvement = 0;  ///< 1 - held misfit / baseline held misfit
  double explained = 0;    ///< explained_share of the misfit beyond the noise
  double bic = 0;
  bool clear = false;   ///< passes every test but min_explained
  bool passes = false;  ///< passes every test
};

struct Selection {
  double misfit = 0;         ///< baseline held-out misfit / noise_misfit
  double design_effect = 1;  ///< deff; std of every fit are to be widened by sqrt(deff)
  double baseline_bic = 0;
  std::vector<RankedEffect> ranked;  ///< fits that were made (ok): passing first, then by held-out misfit
  /// Share of bootstrap resamples in which the best passing effect still improves by
  /// min_improvement (0 when none passes).
  double stability = 0;
  bool named = false;          ///< ranked.front() is the effect to name
  bool has_runner_up = false;  ///< runner_up is meaningful
  std::size_t runner_up = 0;   ///< effect index of the rival that fits almost as well
  /// When nothing is named but an effect came close: why it was not named, one sentence that
  /// starts with the effect's index (the caller adds names) -- see not_named_sentence.
  bool has_near_miss = false;
  std::size_t near_miss = 0;
  bool near_miss_unstable = false;  ///< true: it passed but did not hold under the bootstrap
};

/// Ranks the effects and decides. `residual_clusters` gives the cluster of every fitting
/// residual scalar (all fits share the order); empty: residuals are independent (deff 1).
Selection select_effect(const FitEvidence& baseline, const std::vector<FitEvidence>& effects, double noise_misfit,
                        const std::vector<int>& residual_clusters, const SelectionRules& rules = {});

/// The sentence that says why the near miss was not named ("" when there is none), in the
/// misfit's word ("rms", "misfit", ...) and with `form_hint` saying what else the rest may be.
std::string not_named_sentence(const Selection& selection, const std::vector<std::string>& effect_names,
                               const std::string& misfit_word, const std::string& form_hint,
                               const SelectionRules& rules = {});

/// The verdict when nothing is named: `unknown` for a misfit >= unknown_misfit that was located,
/// else `consistent` (diagnosis-v1 `effect`).
bool unexplained_misfit_is_unknown(const Selection& selection, bool located, const SelectionRules& rules = {});

}  // namespace pliant::host
