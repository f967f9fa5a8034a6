// `pliant diagnose`: the JSON contract on a simulated recording with no hidden effect, and the
// clear refusals (malformed recording, too few frames, nothing moving).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"

namespace pliant::cli_test {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(cli_diagnose, ElasticRecordingIsConsistentAndTheJsonFollowsTheSpec) {
  TempDir dir;
  const std::string recording = dir / "press";
  ASSERT_EQ(run_pliant("simulate foam_press -o " + quoted(recording) + " --beta 0.4 --noise 0.005 --seed 3").status, 0);
  const std::string report = dir / "report";
  const CommandResult r = run_pliant("diagnose " + quoted(recording) + " -q --json - --report " + quoted(report));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("format"), "pliant-diagnosis");
  EXPECT_EQ(j.at("version"), 1);
  EXPECT_EQ(j.at("verdict"), "consistent");
  EXPECT_EQ(j.at("effect"), "none");
  EXPECT_EQ(j.at("improvement"), 0.0);
  EXPECT_EQ(j.at("augmented"), j.at("baseline"));
  EXPECT_EQ(j.at("baseline").at("model"), "msm");
  EXPECT_NEAR(j.at("baseline").at("parameters").at("msm_beta").get<double>(), 0.4, 0.03);
  EXPECT_GT(j.at("noise_rms").get<double>(), 0.0);
  EXPECT_FALSE(j.at("explanation").get<std::string>().empty());
  for (const char* key : {"recording", "location", "candidates"}) EXPECT_TRUE(j.contains(key)) << key;
  ASSERT_FALSE(j.at("candidates").empty());
  for (const auto& c : j.at("candidates")) {
    for (const char* key : {"effect", "rms", "bic", "parameters"}) EXPECT_TRUE(c.contains(key)) << key;
  }
  EXPECT_TRUE(fs::exists(fs::path(report) / "index.html"));
}

TEST(cli_diagnose, MalformedRecordingExitsTwoWithoutJson) {
  TempDir dir;
  const fs::path recording = dir.path() / "rec";
  write_tiny_recording(recording);
  replace_in_file(recording / "particles.csv", "0.1,3,1,0.9", "0.1,9,1,0.9");
  const std::string out = dir / "out.json";
  const CommandResult r = run_pliant("diagnose " + quoted(recording.string()) + " -q --json " + quoted(out));
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "particles.csv:")) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(cli_diagnose, TooFewFramesIsRefusedWithAReason) {
  TempDir dir;
  const fs::path recording = dir.path() / "rec";
  write_tiny_recording(recording);
  const CommandResult r = run_pliant("diagnose " + quoted(recording.string()) + " -q");
  EXPECT_EQ(r.status, 1);
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_TRUE(contains(r.err, "too few frames")) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST(cli_diagnose, MotionlessRecordingIsRefusedNotGivenAVerdict) {
  TempDir dir;
  const fs::path recording = dir.path() / "rec";
  fs::create_directories(recording);
  write_text(recording / "recording.json", tiny_recording_json());
  std::string csv = "t,id,x,y\n";
  for (int k = 0; k < 20; ++k) {
    const std::string t = std::to_string(0.1 * k);
    csv += t + ",0,0,0\n" + t + ",1,1,0\n" + t + ",2,0,1\n" + t + ",3,1,1\n";
  }
  write_text(recording / "particles.csv", csv);
  const CommandResult r = run_pliant("diagnose " + quoted(recording.string()) + " -q");
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.err, "nothing moves")) << r.err;
}

TEST(cli_diagnose, FemModelIsAUsageErrorForNow) {
  TempDir dir;
  const fs::path recording = dir.path() / "rec";
  write_tiny_recording(recording);
  const CommandResult r = run_pliant("diagnose " + quoted(recording.string()) + " --model fem");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "fem")) << r.err;
}

}  // namespace
}  // namespace pliant::cli_test
