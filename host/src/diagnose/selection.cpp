#include "pliant/host/diagnose/selection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "pliant/host/diagnose/holdout.hpp"
#include "words.hpp"

namespace pliant::host {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void check_evidence(const FitEvidence& baseline, const std::vector<FitEvidence>& effects,
                    const std::vector<int>& clusters) {
  if (!clusters.empty() && static_cast<Eigen::Index>(clusters.size()) != baseline.fit_residuals.size()) {
    throw std::invalid_argument("select_effect: one cluster per fitting residual is needed");
  }
  for (const FitEvidence& f : effects) {
    if (!f.ok) continue;
    if (f.held_blocks.size() != baseline.held_blocks.size() ||
        f.fit_residuals.size() != baseline.fit_residuals.size()) {
      throw std::invalid_argument("select_effect: every fit must be scored on the same frames");
    }
    if (f.std.size() != f.values.size() || f.nulls.size() != f.values.size()) {
      throw std::invalid_argument("select_effect: values, std and nulls differ in size");
    }
  }
}

// Design effect (Kish 1965) of residuals in clusters: 1 + (m - 1) icc, m the mean number of
// residuals per cluster and icc the share of their variance that persists within a cluster.
double design_effect(const Eigen::VectorXd& residuals, const std::vector<int>& clusters) {
  if (clusters.empty()) return 1.0;
  const int cluster_count = *std::max_element(clusters.begin(), clusters.end()) + 1;
  std::vector<double> sums(static_cast<std::size_t>(cluster_count), 0.0);
  std::vector<long> counts(static_cast<std::size_t>(cluster_count), 0);
  for (Eigen::Index j = 0; j < residuals.size(); ++j) {
    const auto c = static_cast<std::size_t>(clusters[static_cast<std::size_t>(j)]);
    sums[c] += residuals(j);
    ++counts[c];
  }
  double between = 0;
  long used = 0;
  for (std::size_t c = 0; c < counts.size(); ++c) {
    if (counts[c] == 0) continue;
    ++used;
    between += sums[c] * sums[c] / static_cast<double>(counts[c]);
  }
  const double total = residuals.squaredNorm();
  if (used == 0 || !(total > 0)) return 1.0;
  const double per_cluster = static_cast<double>(residuals.size()) / static_cast<double>(used);
  if (!(per_cluster > 1.0)) return 1.0;
  const double icc = std::clamp((between / total - 1.0 / per_cluster) / (1.0 - 1.0 / per_cluster), 0.0, 1.0);
  return 1.0 + (per_cluster - 1.0) * icc;
}

// Bayesian information criterion of a fit over n residual scalars worth n_eff independent ones.
double information_criterion(const FitEvidence& fit, double n, double n_eff) {
  const double rss = fit.fit_residuals.squaredNorm();
  return n > 0 && rss > 0 ? n_eff * std::log(rss / n) + fit.fitted * std::log(n_eff) : 0.0;
}

double largest_significance(const FitEvidence& fit, double deff) {
  double significance = 0;
  for (std::size_t p = 0; p < fit.values.size(); ++p) {
    const double std = fit.std[p] * std::sqrt(deff);
    if (std::isfinite(fit.nulls[p]) && std::isfinite(std) && std > 0) {
      significance = std::max(significance, std::abs(fit.values[p] - fit.nulls[p]) / std);
    }
  }
  return significance;
}

// Block bootstrap of the held-out frames (fixed seed): resamples of the held-out blocks, each
// re-scoring the fits already made. Fills the stability of ranked.front() and the rival that
// most often has the lowest held-out misfit instead.
void bootstrap(const FitEvidence& baseline, const std::vector<FitEvidence>& effects, const SelectionRules& rules,
               Selection& out) {
  std::vector<std::size_t> passing;
  for (const RankedEffect& r : out.ranked) {
    if (r.passes) passing.push_back(r.effect);
  }
  const std::size_t blocks = baseline.held_blocks.size();
  if (passing.empty() || blocks == 0) return;
  std::mt19937_64 random(0x5eed);
  std::uniform_int_distribution<std::size_t> pick(0, blocks - 1);
  std::vector<int> wins(passing.size(), 0);
  int explains = 0;
  std::vector<std::size_t> sample(blocks);
  auto misfit_of = [&](const std::vector<HeldBlock>& per_block) {
    double rss = 0;
    long count = 0;
    for (std::size_t s : sample) {
      rss += per_block[s].rss;
      count += per_block[s].count;
    }
    return count > 0 ? std::sqrt(rss / static_cast<double>(count)) : 0.0;
  };
  for (int b = 0; b < rules.bootstrap_resamples; ++b) {
    for (std::size_t& s : sample) s = pick(random);
    const double base = misfit_of(baseline.held_blocks);
    std::size_t winner = 0;
    double winner_misfit = kInf;
    for (std::size_t c = 0; c < passing.size(); ++c) {
      const double misfit = misfit_of(effects[passing[c]].held_blocks);
      if (c == 0 && base > 0 && 1.0 - misfit / base >= rules.min_improvement) ++explains;
      if (misfit < winner_misfit) {
        winner_misfit = misfit;
        winner = c;
      }
    }
    ++wins[winner];
  }
  const double resamples = static_cast<double>(std::max(rules.bootstrap_resamples, 1));
  out.stability = explains / resamples;
  double rival_share = 0;
  for (std::size_t c = 1; c < passing.size(); ++c) {
    const double share = wins[c] / resamples;
    if (share > rival_share) {
      rival_share = share;
      out.runner_up = passing[c];
    }
  }
  out.has_runner_up = rival_share >= rules.rival_share;
}

}  // namespace

std::vector<int> held_block_of_frame(const std::vector<unsigned char>& held_out, int& block_count) {
  std::vector<int> block_of(held_out.size(), -1);
  block_count = 0;
  for (std::size_t k = 0; k < held_out.size(); ++k) {
    if (held_out[k] == 0) continue;
    if (k == 0 || held_out[k - 1] == 0) ++block_count;
    block_of[k] = block_count - 1;
  }
  return block_of;
}

double FitEvidence::held_misfit() const {
  double rss = 0;
  long count = 0;
  for (const HeldBlock& b : held_blocks) {
    rss += b.rss;
    count += b.count;
  }
  return count > 0 ? std::sqrt(rss / static_cast<double>(count)) : 0.0;
}

Selection select_effect(const FitEvidence& baseline, const std::vector<FitEvidence>& effects, double noise_misfit,
                        const std::vector<int>& residual_clusters, const SelectionRules& rules) {
  check_evidence(baseline, effects, residual_clusters);
  Selection out;
  const double base_misfit = baseline.held_misfit();
  out.misfit = noise_misfit > 0 ? base_misfit / noise_misfit : kInf;

  // Every score counts the residuals as worth n / deff independent samples, deff the design
  // effect of the best-fitting model's residuals (the same for all, so that the scores compare).
  const FitEvidence* best = &baseline;
  for (const FitEvidence& f : effects) {
    if (f.ok && f.fit_residuals.squaredNorm() < best->fit_residuals.squaredNorm()) best = &f;
  }
  out.design_effect = design_effect(best->fit_residuals, residual_clusters);
  const double n = static_cast<double>(baseline.fit_residuals.size());
  const double n_eff = n / out.design_effect;
  out.baseline_bic = information_criterion(baseline, n, n_eff);

  for (std::size_t e = 0; e < effects.size(); ++e) {
    const FitEvidence& f = effects[e];
    if (!f.ok) continue;
    RankedEffect r;
    r.effect = e;
    r.significance = largest_significance(f, out.design_effect);
    r.improvement = base_misfit > 0 ? 1.0 - f.held_misfit() / base_misfit : 0.0;
    r.bic = information_criterion(f, n, n_eff);
    r.explained = explained_share(base_misfit, f.held_misfit(), noise_misfit);
    r.clear = out.misfit >= rules.min_misfit && r.improvement >= rules.min_improvement &&
              out.baseline_bic - r.bic >= rules.min_bic_gain && r.significance >= rules.min_significance;
    r.passes = r.clear && r.explained >= rules.min_explained;
    out.ranked.push_back(r);
  }
  std::stable_sort(out.ranked.begin(), out.ranked.end(), [&](const RankedEffect& a, const RankedEffect& b) {
    if (a.passes != b.passes) return a.passes;
    return effects[a.effect].held_misfit() < effects[b.effect].held_misfit();
  });

  const bool passes = !out.ranked.empty() && out.ranked.front().passes;
  if (passes) bootstrap(baseline, effects, rules, out);
  out.named = passes && out.stability >= rules.stable_share;
  if (out.named && !out.has_runner_up && out.ranked.size() > 1 && out.ranked[1].passes &&
      out.ranked[1].bic - out.ranked.front().bic < rules.close_bic) {
    out.has_runner_up = true;
    out.runner_up = out.ranked[1].effect;
  }
  if (!out.named) {
    if (passes) {
      out.has_near_miss = true;
      out.near_miss = out.ranked.front().effect;
      out.near_miss_unstable = true;
    } else {
      for (const RankedEffect& r : out.ranked) {
        if (!r.clear) continue;
        out.has_near_miss = true;
        out.near_miss = r.effect;
        break;
      }
    }
  }
  return out;
}

std::string not_named_sentence(const Selection& selection, const std::vector<std::string>& effect_names,
                               const std::string& misfit_word, const std::string& form_hint,
                               const SelectionRules& rules) {
  if (!selection.has_near_miss) return "";
  const std::string& name = effect_names.at(selection.near_miss);
  if (selection.near_miss_unstable) {
    return " " + name + " improves the fit on some held-out frames but not on " +
           words::number(100.0 * rules.stable_share) + " % of resamples of them (" +
           words::number(100.0 * selection.stability) + " %).";
  }
  for (const RankedEffect& r : selection.ranked) {
    if (r.effect != selection.near_miss) continue;
    return " " + name + " improves the held-out " + misfit_word + " by " + words::number(100.0 * r.improvement) +
           " % but explains only " + words::number(100.0 * r.explained) +
           " % of the misfit beyond the noise: the rest is not a catalogued effect, or the model's form is off" +
           form_hint + ".";
  }
  return "";
}

bool unexplained_misfit_is_unknown(const Selection& selection, bool located, const SelectionRules& rules) {
  return selection.misfit >= rules.unknown_misfit && located;
}

}  // namespace pliant::host
