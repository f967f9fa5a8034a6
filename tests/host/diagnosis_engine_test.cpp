// The diagnosis pipeline (engine.hpp) on a made-up model: the steps run in order, each once;
// what is named, and the words and evidence around it, follow from the adapter's fits alone.
// The MSM and FEM adapters are covered end to end by diagnose_test, fem_diagnose_test and the
// concealed suites.
#include "pliant/host/diagnose/engine.hpp"

#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "synthetic_evidence.hpp"

namespace {

using pliant::host::Candidate;
using pliant::host::DiagnoseOptions;
using pliant::host::DiagnoseResult;
using pliant::host::Diagnosis;
using pliant::host::DiagnosisEvidence;
using pliant::host::DiagnosisModel;
using pliant::host::FitEvidence;
using pliant::host::RankedEffect;
using pliant::host::run_diagnosis;
using pliant::host::UnexplainedWords;
using pliant::host::testing::effect_with;
using pliant::host::testing::fit_with;

// A model whose baseline and effects are given fits; it records what the pipeline asked.
class MadeUpModel final : public DiagnosisModel {
 public:
  MadeUpModel(FitEvidence baseline, std::vector<std::pair<std::string, FitEvidence>> effects, bool located)
      : baseline_(std::move(baseline)), effects_(std::move(effects)), located_(located) {}

  void fit_baseline(Diagnosis& out) override {
    calls.push_back("fit_baseline");
    out.noise_rms = 1.0;
    out.baseline.model = "made_up";
    out.baseline.rms = baseline_.held_misfit();
  }
  std::map<std::string, double> locate(Diagnosis& out) override {
    calls.push_back("locate");
    if (located_) out.location.particles = {3, 4};
    return {{"made_up_signature", 7.0}};
  }
  std::vector<std::string> catalogue() override {
    calls.push_back("catalogue");
    std::vector<std::string> names;
    for (const auto& e : effects_) names.push_back(e.first);
    return names;
  }
  void fit_effects(int, const std::function<void()>& one_done) override {
    calls.push_back("fit_effects");
    for (std::size_t e = 0; e < effects_.size(); ++e) one_done();
  }
  FitEvidence baseline_evidence() const override { return baseline_; }
  FitEvidence effect_evidence(std::size_t e) const override { return effects_[e].second; }
  double noise_misfit() const override { return 1.0; }
  std::vector<int> residual_clusters() const override { return clusters; }
  Candidate candidate(std::size_t e, const RankedEffect& ranked, double) const override {
    Candidate c;
    c.effect = effects_[e].first;
    c.rms = effects_[e].second.held_misfit();
    c.bic = ranked.bic;
    c.explained = ranked.explained;
    return c;
  }
  void explain_named(std::size_t e, Diagnosis& out) const override {
    named_index = static_cast<int>(e);
    out.explanation = "named " + effects_[e].first;
    out.improvement = 1.0 - effects_[e].second.held_misfit() / baseline_.held_misfit();
  }
  UnexplainedWords unexplained_words(const Diagnosis&) const override {
    return {"The made-up model", "particles 3-4", "9 mm rms", "rms", ""};
  }
  void fill_evidence(bool named, std::size_t e, DiagnosisEvidence& evidence) const override {
    evidence.length_unit = named ? "named " + effects_[e].first : "baseline";
  }
  int simulations() const override { return 42; }

  std::vector<std::string> calls;
  std::vector<int> clusters;
  mutable int named_index = -1;

 private:
  FitEvidence baseline_;
  std::vector<std::pair<std::string, FitEvidence>> effects_;
  bool located_;
};

DiagnoseResult run(MadeUpModel& model, std::vector<std::string>* progress = nullptr) {
  DiagnoseOptions options;
  if (progress != nullptr) {
    options.progress = [progress](const std::string& stage, int done, int total) {
      progress->push_back(stage + " " + std::to_string(done) + "/" + std::to_string(total));
    };
  }
  return run_diagnosis(model, "made_up_recording", options);
}

TEST(DiagnosisEngine, RunsTheStepsInOrderAndNamesTheEffectThatExplainsTheMisfit) {
  MadeUpModel model(fit_with(4.0, 1, 1),
                    {{"creep", effect_with(3.9, 0.5, 0.01, 2)}, {"sag", effect_with(1.02, 0.5, 0.01, 3)}}, true);
  std::vector<std::string> progress;
  const DiagnoseResult result = run(model, &progress);
  EXPECT_EQ(model.calls, (std::vector<std::string>{"fit_baseline", "locate", "catalogue", "fit_effects"}));
  EXPECT_EQ(progress,
            (std::vector<std::string>{"baseline 0/1", "baseline 1/1", "effects 0/2", "effects 1/2", "effects 2/2"}));
  const Diagnosis& d = result.diagnosis;
  EXPECT_EQ(d.recording, "made_up_recording");
  EXPECT_EQ(d.verdict, "missing_physics");
  EXPECT_EQ(d.effect, "sag");
  EXPECT_EQ(model.named_index, 1);
  EXPECT_EQ(d.explanation, "named sag");
  ASSERT_EQ(d.candidates.size(), 2U);
  EXPECT_EQ(d.candidates.front().effect, "sag");  // the passing candidate first
  EXPECT_GE(d.selection_stability, 0.99);
  EXPECT_EQ(result.evidence.length_unit, "named sag");
  EXPECT_EQ(result.evidence.signatures.at("made_up_signature"), 7.0);
  EXPECT_EQ(result.evidence.signatures.at("simulations"), 42.0);
  EXPECT_NEAR(result.evidence.signatures.at("misfit_over_noise"), 4.0, 0.3);
  EXPECT_EQ(result.evidence.signatures.count("design_effect"), 0U);  // no clusters given
}

TEST(DiagnosisEngine, ALargeLocatedMisfitNoEffectExplainsIsUnknown) {
  MadeUpModel model(fit_with(9.0, 1, 1), {{"creep", effect_with(8.9, 0.5, 0.01, 2)}}, true);
  model.clusters.assign(pliant::host::testing::kSyntheticResiduals, 0);
  for (std::size_t j = 0; j < model.clusters.size(); ++j) model.clusters[j] = static_cast<int>(j / 10);
  const DiagnoseResult result = run(model);
  const Diagnosis& d = result.diagnosis;
  EXPECT_EQ(d.verdict, "missing_physics");
  EXPECT_EQ(d.effect, "unknown");
  EXPECT_EQ(model.named_index, -1);
  EXPECT_EQ(d.explanation.rfind("The made-up model misses particles 3-4 by 9 mm rms, ", 0), 0U) << d.explanation;
  EXPECT_EQ(d.improvement, 0.0);
  EXPECT_EQ(d.augmented.model, "made_up");  // the baseline stands
  EXPECT_EQ(result.evidence.length_unit, "baseline");
  EXPECT_EQ(result.evidence.signatures.count("design_effect"), 1U);
}

TEST(DiagnosisEngine, AMisfitThatIsNotLocatedIsConsistentAndSaysWhatCameClose) {
  // The effect halves the misfit beyond the noise: clear, but it explains too little to name.
  MadeUpModel model(fit_with(10.0, 1, 1), {{"creep", effect_with(6.0, 0.5, 0.01, 2)}}, false);
  const Diagnosis d = run(model).diagnosis;
  EXPECT_EQ(d.verdict, "consistent");
  EXPECT_EQ(d.effect, "none");
  EXPECT_NE(d.explanation.find("The made-up model explains the recording to within"), std::string::npos);
  EXPECT_NE(d.explanation.find("creep improves the held-out rms by"), std::string::npos) << d.explanation;
  EXPECT_NE(d.explanation.find("explains only"), std::string::npos) << d.explanation;
}

}  // namespace
