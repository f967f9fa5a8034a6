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
      {"foam_press --beta 1.5", "--beta"},   {"foam_press --beta -0.1", "--beta"},
      {"foam_press --alpha 0", "--alpha"},   {"foam_press --noise -1", "--noise"},
      {"foam_press --rate 0", "--rate"},     {"foam_press --rate 1e9", "--rate"},
      {"foam_press --seed -3", "--seed"},    {"foam_press --beta soft", "--beta"},
      {"jelly_wobble", "jelly_wobble"},
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

}  // namespace
}  // namespace pliant::cli_test
