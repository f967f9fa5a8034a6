// simulate -> estimate: the command line recovers a known msm_beta and writes outputs-v1 JSON.
#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"

namespace pliant::cli_test {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// One simulated foam press shared by the tests in this file (simulation is deterministic).
class cli_roundtrip : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    const CommandResult r =
        run_pliant("simulate foam_press -o " + quoted(recording()) + " --beta 0.3 --noise 0.005 --seed 7");
    ASSERT_EQ(r.status, 0) << r.err;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static std::string recording() { return *dir_ / "foam_press_03"; }
  static std::string scratch(const std::string& name) { return *dir_ / name; }

  static TempDir* dir_;
};
TempDir* cli_roundtrip::dir_ = nullptr;

void expect_estimate_document(const nlohmann::json& doc, const std::string& mode) {
  EXPECT_EQ(doc.at("format"), "pliant-estimate");
  EXPECT_EQ(doc.at("version"), 1);
  EXPECT_EQ(doc.at("recording"), "foam_press_03");
  EXPECT_EQ(doc.at("model"), "msm");
  EXPECT_EQ(doc.at("mode"), mode);
  const double beta = doc.at("parameters").at("msm_beta").get<double>();
  const double alpha = doc.at("parameters").at("msm_alpha").get<double>();
  EXPECT_TRUE(beta >= 0.0 && beta <= 1.0) << beta;
  EXPECT_TRUE(alpha > 0.0 && alpha <= 1.0) << alpha;
  EXPECT_GT(doc.at("uncertainty").at("msm_beta").get<double>(), 0.0);
  EXPECT_TRUE(doc.at("unique_minimum").is_boolean());
  EXPECT_GT(doc.at("rms").get<double>(), 0.0);
  const std::vector<double> curve_beta = doc.at("curve").at("msm_beta").get<std::vector<double>>();
  const std::vector<double> curve_error = doc.at("curve").at("error").get<std::vector<double>>();
  EXPECT_EQ(curve_beta.size(), curve_error.size());
  EXPECT_GE(curve_beta.size(), 11u);
  for (std::size_t i = 1; i < curve_beta.size(); ++i) EXPECT_LT(curve_beta[i - 1], curve_beta[i]) << i;
  for (double e : curve_error) EXPECT_TRUE(std::isfinite(e) && e >= 0.0) << e;
}

TEST_F(cli_roundtrip, EstimateRecoversBetaAndWritesJson) {
  const std::string json_path = scratch("estimate.json");
  const CommandResult r = run_pliant("estimate " + quoted(recording()) + " --json " + quoted(json_path));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const nlohmann::json doc = nlohmann::json::parse(read_text(json_path));
  expect_estimate_document(doc, "trajectory");
  EXPECT_NEAR(doc.at("parameters").at("msm_beta").get<double>(), 0.3, 0.03);
  EXPECT_DOUBLE_EQ(doc.at("parameters").at("msm_alpha").get<double>(), 1.0);

  // Atomic write: nothing but the document is left beside it.
  for (const auto& entry : fs::directory_iterator(fs::path(json_path).parent_path())) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  }
  // The summary names the recording, the estimate and the error curve.
  EXPECT_TRUE(contains(r.out, "foam_press_03")) << r.out;
  EXPECT_TRUE(contains(r.out, "msm_beta")) << r.out;
  EXPECT_TRUE(contains(r.out, "±")) << r.out;
  EXPECT_TRUE(contains(r.out, "unique min")) << r.out;
  EXPECT_TRUE(contains(r.out, "<- estimate")) << r.out;
  EXPECT_TRUE(contains(r.out, " px")) << r.out;
}

TEST_F(cli_roundtrip, JsonDashPrintsOnlyValidJson) {
  const CommandResult r = run_pliant("estimate " + quoted(recording()) + " --json -");
  ASSERT_EQ(r.status, 0) << r.err;
  nlohmann::json doc;
  ASSERT_NO_THROW(doc = nlohmann::json::parse(r.out)) << r.out;
  expect_estimate_document(doc, "trajectory");
  EXPECT_NEAR(doc.at("parameters").at("msm_beta").get<double>(), 0.3, 0.03);
}

TEST_F(cli_roundtrip, AlphaFlagEstimatesAlphaToo) {
  const CommandResult r = run_pliant("estimate " + quoted(recording()) + " --alpha --json -");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json doc = nlohmann::json::parse(r.out);
  expect_estimate_document(doc, "trajectory");
  EXPECT_TRUE(doc.at("model_options").at("msm_alpha_estimated").get<bool>());
  EXPECT_NEAR(doc.at("parameters").at("msm_alpha").get<double>(), 1.0, 0.1);
}

TEST_F(cli_roundtrip, GivenAlphaIsUsed) {
  const CommandResult r = run_pliant("estimate " + quoted(recording()) + " --msm-alpha 0.5 --json -");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json doc = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(doc.at("parameters").at("msm_alpha").get<double>(), 0.5);
  EXPECT_FALSE(doc.at("model_options").at("msm_alpha_estimated").get<bool>());
}

TEST_F(cli_roundtrip, FinalModeRuns) {
  const CommandResult r = run_pliant("estimate " + quoted(recording()) + " --mode final --json -");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_estimate_document(nlohmann::json::parse(r.out), "final");
}

TEST_F(cli_roundtrip, UnwritableJsonPathExitsOneWithOneLine) {
  const std::string json_path = scratch("no_such_dir/estimate.json");
  const CommandResult r = run_pliant("estimate " + quoted(recording()) + " --json " + quoted(json_path));
  EXPECT_EQ(r.status, 1);
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_TRUE(contains(r.err, "pliant estimate: cannot write")) << r.err;
  EXPECT_TRUE(contains(r.err, json_path)) << r.err;
}

}  // namespace
}  // namespace pliant::cli_test
