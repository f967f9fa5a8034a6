// `pliant simulate`: what it writes, what it refuses.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"

namespace pliant::cli_test {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(cli_simulate, WritesRecordingAndTruthAndSaysSoInOneLine) {
  TempDir dir;
  const std::string out = dir / "press";
  const CommandResult r = run_pliant("simulate foam_press -o " + quoted(out) + " --beta 0.7 --noise 0.01 --seed 9");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  ASSERT_EQ(lines_of(r.out).size(), 1u) << r.out;
  EXPECT_TRUE(contains(r.out, out)) << r.out;
  EXPECT_TRUE(fs::exists(fs::path(out) / "recording.json"));
  EXPECT_TRUE(fs::exists(fs::path(out) / "particles.csv"));
  const nlohmann::json truth = nlohmann::json::parse(read_text(fs::path(out) / "truth.json"));
  EXPECT_DOUBLE_EQ(truth.at("parameters").at("msm_beta").get<double>(), 0.7);
  EXPECT_DOUBLE_EQ(truth.at("noise_fraction_of_spacing").get<double>(), 0.01);
  EXPECT_EQ(truth.at("seed").get<int>(), 9);
}

TEST(cli_simulate, RefusesNonEmptyDirectoryWithoutForce) {
  TempDir dir;
  write_text(dir / "notes.txt", "keep me\n");
  const CommandResult refused = run_pliant("simulate foam_press -o " + quoted(dir.path().string()));
  EXPECT_EQ(refused.status, 2);
  ASSERT_EQ(refused.err_lines().size(), 1u) << refused.err;
  EXPECT_TRUE(contains(refused.err, "pliant simulate: ")) << refused.err;
  EXPECT_TRUE(contains(refused.err, "--force")) << refused.err;
  EXPECT_FALSE(fs::exists(dir.path() / "recording.json"));
  EXPECT_EQ(read_text(dir.path() / "notes.txt"), "keep me\n");

  const CommandResult forced = run_pliant("simulate foam_press --force -o " + quoted(dir.path().string()));
  EXPECT_EQ(forced.status, 0) << forced.err;
  EXPECT_TRUE(fs::exists(dir.path() / "recording.json"));
}

TEST(cli_simulate, WritesIntoAnExistingEmptyDirectory) {
  TempDir dir;
  const CommandResult r = run_pliant("simulate cantilever_strip -o " + quoted(dir.path().string()));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir.path() / "truth.json"));
}

TEST(cli_simulate, RefusesAFileAsOutput) {
  TempDir dir;
  write_text(dir / "file", "x");
  const CommandResult r = run_pliant("simulate foam_press --force -o " + quoted(dir / "file"));
  EXPECT_EQ(r.status, 2);
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_TRUE(contains(r.err, "not a directory")) << r.err;
}

struct BadValue {
  std::string arguments;  // after `simulate`, before -o
  std::string mentions;
};

TEST(cli_simulate, BadValuesExitTwoWithOneLineAndWriteNothing) {
  const std::vector<BadValue> cases = {
      {"foam_press --beta 1.5", "--beta"},
      {"foam_press --beta -0.1", "--beta"},
      {"foam_press --alpha 0", "--alpha"},
      {"foam_press --noise -1", "--noise"},
      {"foam_press --rate 0", "--rate"},
      {"foam_press --rate 1e9", "--rate"},
      {"foam_press --seed -3", "--seed"},
      {"foam_press --beta soft", "--beta"},
      {"jelly_wobble", "jelly_wobble"},
      {"foam_press --effect plastic", "plasticity, viscosity, friction, gravity, heterogeneity, stiffening"},
      {"foam_press --effect plasticity:foo=1", "yield, creep, max"},
      {"foam_press --effect plasticity:yield", "param=value"},
      {"foam_press --effect heterogeneity:region=middle", "inclusion, left, right"},
      {"foam_press --effect gravity:g=-2", "g must be >= 0"},
      {"foam_press --effect viscosity:tau=0", "tau"},
      {"foam_press --effect ''", "--effect"},
      {"foam_press --substeps 0", "--substeps"},
      {"foam_press --substeps 100", "--substeps"},
      {"foam_press --cluster-radius 0.5", "--cluster-radius"},
      {"foam_press --occlusion 0.8", "--occlusion"},
      {"foam_press --occlusion -0.1", "--occlusion"},
      {"foam_press --depth 0", "--depth"},
      {"foam_press --depth 3", "--depth"},
  };
  for (const BadValue& c : cases) {
    TempDir dir;
    const std::string out = dir / "rec";
    const CommandResult r = run_pliant("simulate " + c.arguments + " -o " + quoted(out));
    EXPECT_EQ(r.status, 2) << c.arguments;
    ASSERT_EQ(r.err_lines().size(), 1u) << c.arguments << ": " << r.err;
    EXPECT_EQ(r.err.rfind("pliant simulate: ", 0), 0u) << r.err;
    EXPECT_TRUE(contains(r.err, c.mentions)) << c.arguments << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.arguments;
  }
}

TEST(cli_simulate, ConcealedEffectLeavesNoTraceInTheRecording) {
  TempDir dir;
  const std::string out = dir / "case";
  const CommandResult r = run_pliant("simulate cantilever_strip -o " + quoted(out) +
                                     " --effect gravity:g=0.02 --substeps 2 --cluster-radius 1.8 --occlusion 0.1"
                                     " --noise 0.005 --seed 3");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const std::string word : {"effect", "gravity", "substeps", "occlusion", "1.8"}) {
    EXPECT_FALSE(contains(r.out, word)) << r.out;
  }
  const std::string json = read_text(fs::path(out) / "recording.json");
  const std::string csv = read_text(fs::path(out) / "particles.csv");
  for (const std::string word : {"effect", "gravity"}) {
    EXPECT_FALSE(contains(json, word)) << json;
    EXPECT_FALSE(contains(csv, word));
  }
  const nlohmann::json truth = nlohmann::json::parse(read_text(fs::path(out) / "truth.json"));
  EXPECT_EQ(truth.at("effect").get<std::string>(), "gravity");
  EXPECT_DOUBLE_EQ(truth.at("effect_parameters").at("g").get<double>(), 0.02);
  EXPECT_EQ(truth.at("steps_per_frame").get<int>(), 2);
  EXPECT_DOUBLE_EQ(truth.at("cluster_radius_factor").get<double>(), 1.8);
  EXPECT_DOUBLE_EQ(truth.at("occlusion").get<double>(), 0.1);
  EXPECT_GT(truth.at("occluded_observations").get<int>(), 0);

  // Missing rows, and the recording still reads: estimate accepts it.
  const CommandResult estimate = run_pliant("estimate " + quoted(out));
  EXPECT_EQ(estimate.status, 0) << estimate.err;
}

TEST(cli_simulate, NewScenariosAndReleaseWriteDrivenWindowsThatEnd) {
  for (const std::string arguments :
       {"ring_squeeze", "dome_press", "foam_press --release --depth 0.1", "block_press --release"}) {
    TempDir dir;
    const std::string out = dir / "rec";
    const CommandResult r = run_pliant("simulate " + arguments + " -o " + quoted(out));
    ASSERT_EQ(r.status, 0) << arguments << ": " << r.err;
    const nlohmann::json json = nlohmann::json::parse(read_text(fs::path(out) / "recording.json"));
    const nlohmann::json& driven = json.at("particles").at("driven");
    ASSERT_EQ(driven.size(), 1u) << arguments;
    EXPECT_TRUE(driven[0].contains("to")) << arguments << ": " << driven.dump();
    EXPECT_FALSE(json.at("particles").at("fixed").empty()) << arguments;
  }
}

}  // namespace
}  // namespace pliant::cli_test
