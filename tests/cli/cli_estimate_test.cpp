// `pliant estimate` on well-formed recordings that cannot be estimated, or only doubtfully.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"

namespace pliant::cli_test {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(cli_estimate, EveryParticleFixedExitsOneWithOneLine) {
  TempDir dir;
  const fs::path recording = dir.path() / "rec";
  write_tiny_recording(recording);
  replace_in_file(recording / "recording.json", "\"fixed\": [0, 1]", "\"fixed\": [0, 1, 2, 3]");
  const CommandResult r = run_pliant("estimate " + quoted(recording.string()));
  EXPECT_EQ(r.status, 1);
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("pliant estimate: ", 0), 0u) << r.err;
  EXPECT_TRUE(contains(r.err, "every particle is fixed")) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST(cli_estimate, UnknownKeysAreWarningsNotErrors) {
  TempDir dir;
  const fs::path recording = dir.path() / "rec";
  write_tiny_recording(recording);
  replace_in_file(recording / "recording.json", "\"length_unit\": \"m\",",
                  "\"length_unit\": \"m\", \"colour\": \"red\",");
  const CommandResult r = run_pliant("estimate " + quoted(recording.string()) + " --json -");
  EXPECT_EQ(r.status, 0) << r.err;
  // The estimate itself may add warnings about this tiny recording; all are warnings.
  ASSERT_FALSE(r.err_lines().empty());
  for (const std::string& line : r.err_lines()) EXPECT_EQ(line.rfind("pliant: warning: ", 0), 0u) << line;
  EXPECT_TRUE(contains(r.err_lines().front(), "colour")) << r.err;
}

TEST(cli_estimate, MotionlessRecordingIsFlaggedNotIdentifiable) {
  TempDir dir;
  const fs::path recording = dir.path() / "rec";
  write_tiny_recording(recording);
  // Every frame equal to the rest shape: any msm_beta explains it equally well.
  replace_line(recording / "particles.csv", 8, "0.1,2,0,1");
  replace_line(recording / "particles.csv", 9, "0.1,3,1,1");
  replace_line(recording / "particles.csv", 12, "0.2,2,0,1");
  replace_line(recording / "particles.csv", 13, "0.2,3,1,1");

  const CommandResult summary = run_pliant("estimate " + quoted(recording.string()));
  EXPECT_EQ(summary.status, 0) << summary.err;
  EXPECT_TRUE(contains(summary.out, "unique min  no")) << summary.out;
  EXPECT_TRUE(contains(summary.out, "warning: msm_beta is not identifiable")) << summary.out;

  const CommandResult json = run_pliant("estimate " + quoted(recording.string()) + " --json -");
  EXPECT_EQ(json.status, 0) << json.err;
  const nlohmann::json doc = nlohmann::json::parse(json.out);
  EXPECT_FALSE(doc.at("unique_minimum").get<bool>());
  ASSERT_FALSE(json.err_lines().empty());
  EXPECT_TRUE(contains(json.err, "pliant: warning: msm_beta is not identifiable")) << json.err;
}

}  // namespace
}  // namespace pliant::cli_test
