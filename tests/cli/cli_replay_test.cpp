// `pliant replay`: a recording played back through the HAL replay devices, with the online
// estimate, scripted faults, real-time pacing and refusals of bad scripts.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"

namespace pliant::cli_test {
namespace {

const std::string kFoamMedium = std::string(PLIANT_EXAMPLES_DIR) + "/foam_press_medium";

nlohmann::json truth_of(const std::string& recording) {
  return nlohmann::json::parse(read_text(fs::path(recording) / "truth.json"));
}

nlohmann::json last_json_line(const std::string& text) {
  const std::vector<std::string> lines = lines_of(text);
  return nlohmann::json::parse(lines.back());
}

TEST(CliReplay, SteppedReplayDeliversEveryFrameAndEstimatesOnline) {
  const CommandResult r = run_pliant("replay --stepped " + quoted(kFoamMedium));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<std::string> lines = lines_of(r.out);
  const nlohmann::json summary = last_json_line(r.out)["summary"];
  const nlohmann::json particles = summary["devices"]["particles"];
  EXPECT_EQ(lines.size(), particles["samples"].get<std::size_t>() + 1);
  EXPECT_EQ(particles["samples"], 136);
  EXPECT_EQ(particles["dropped"], 0);
  // Sequence numbers 1..136 and stamps on the recorded spacing (30 Hz).
  const nlohmann::json second = nlohmann::json::parse(lines[1]);
  EXPECT_EQ(second["seq"], 2);
  EXPECT_NEAR(second["t"].get<double>(), 1.0 / 30, 1e-9);
  const double truth = truth_of(kFoamMedium)["parameters"]["msm_beta"];
  EXPECT_NEAR(summary["estimate"]["msm_beta"].get<double>(), truth, 0.05);
  EXPECT_EQ(summary["estimate"]["frames"], 135);
  EXPECT_NE(r.err.find("pliant replay: "), std::string::npos);
}

// A press from the independent MSM simulator (tools/concealed/msm_world.py: msm_alpha 0.52,
// three MSM steps per frame, clusters blended by a kernel, 13 % of the observations occluded):
// the online estimate chooses a model form other than alpha 1 at one step and lands on the truth;
// held at alpha 1 and one step, as before, it was 0.19 off.
TEST(CliReplay, TheOnlineEstimateChoosesTheModelFormOnAnotherSimulatorsPress) {
  const std::string press = std::string(PLIANT_EXAMPLES_DIR) + "/concealed_msm_world/case_22";
  const double truth = truth_of(press)["parameters"]["msm_beta"];
  const CommandResult chosen = run_pliant("replay --stepped " + quoted(press));
  ASSERT_EQ(chosen.status, 0) << chosen.err;
  const nlohmann::json estimate = last_json_line(chosen.out)["summary"]["estimate"];
  EXPECT_TRUE(estimate["alpha_fitted"].get<bool>());
  EXPECT_GT(estimate["steps_per_frame"].get<int>(), 1);
  EXPECT_NEAR(estimate["msm_beta"].get<double>(), truth, 0.03);

  const CommandResult held = run_pliant("replay --stepped --msm-alpha 1 " + quoted(press));
  ASSERT_EQ(held.status, 0) << held.err;
  const nlohmann::json old = last_json_line(held.out)["summary"]["estimate"];
  EXPECT_FALSE(old["alpha_fitted"].get<bool>());
  EXPECT_EQ(old["steps_per_frame"].get<int>(), 1);
  EXPECT_GT(std::abs(old["msm_beta"].get<double>() - truth), 0.1);
}

// The quasi-static row beside the stepped ones: on a press that steps once per frame it must not
// take over (the stepped rows explain it) and the estimate stays on the truth.
TEST(CliReplay, TheSettledRowRunsBesideTheSteppedOnes) {
  const CommandResult r = run_pliant("replay --stepped --settled-row 64 " + quoted(kFoamMedium));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json estimate = last_json_line(r.out)["summary"]["estimate"];
  const double truth = truth_of(kFoamMedium)["parameters"]["msm_beta"];
  EXPECT_NEAR(estimate["msm_beta"].get<double>(), truth, 0.05);
  EXPECT_GE(estimate["steps_per_frame"].get<int>(), 1);
  EXPECT_EQ(estimate["frames"], 135);
}

TEST(CliReplay, ScriptedFaultsReachTheDevicesAndAreCounted) {
  TempDir dir;
  write_text(dir / "faults.txt",
             "# a disconnect, a half occlusion and a stale stamp\n"
             "1.0 disconnect observer 0.2\n"
             "2.0 occlude observer 0.5 0.5\n"
             "3.0 stamp_jump observer 0.04 -1\n");
  const CommandResult r = run_pliant("replay --stepped " + quoted(kFoamMedium) + " --faults " +
                                     quoted(dir / "faults.txt") + " -o " + quoted(dir / "out.jsonl"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  const std::string out = read_text(dir / "out.jsonl");
  EXPECT_NE(out.find(R"("error":"disconnected")"), std::string::npos);
  const nlohmann::json summary = last_json_line(out)["summary"];
  const nlohmann::json p = summary["devices"]["particles"];
  EXPECT_EQ(p["disconnects"], 1);
  EXPECT_EQ(p["reconnects"], 1);
  // 0.2 s at 30 Hz: 6 frames lost while disconnected, as with a live sensor.
  EXPECT_GE(p["dropped"].get<int>(), 5);
  EXPECT_LE(p["dropped"].get<int>(), 7);
  EXPECT_EQ(p["samples"].get<int>() + p["dropped"].get<int>(), 136);
  EXPECT_GE(p["injected"]["occlude"].get<int>(), 14);
  EXPECT_GE(p["injected"]["stamp_jump"].get<int>(), 1);
  // The backwards stamp gives the estimator a frame with dt < 0: rejected, counted, survived.
  EXPECT_GE(summary["estimate"]["rejected_frames"].get<int>(), 1);
  const double truth = truth_of(kFoamMedium)["parameters"]["msm_beta"];
  EXPECT_NEAR(summary["estimate"]["msm_beta"].get<double>(), truth, 0.1);
}

TEST(CliReplay, WrenchAndGripperAreReplayedBesideTheParticles) {
  TempDir dir;
  const fs::path rec = dir / "rec";
  write_tiny_recording(rec);
  replace_in_file(rec / "recording.json", R"("particles": "particles.csv" })",
                  R"("particles": "particles.csv", "wrench": "wrench.csv", "gripper": "gripper.csv" },
  "wrench": { "applied_to": [2, 3] })");
  write_text(rec / "wrench.csv",
             "t,fx,fy,fz,tx,ty,tz\n0,0,0,0,0,0,0\n0.05,0,-1,0,0,0,0\n0.1,0,-2,0,0,0,0\n0.15,0,-3,0,0,0,0\n");
  write_text(rec / "gripper.csv", "t,width,force\n0,1,0\n0.1,0.9,2\n0.2,0.85,3\n");
  const CommandResult r = run_pliant("replay --stepped --no-estimate " + quoted(rec.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json summary = last_json_line(r.out)["summary"];
  EXPECT_EQ(summary["devices"]["particles"]["samples"], 3);
  EXPECT_EQ(summary["devices"]["wrench"]["samples"], 4);
  EXPECT_EQ(summary["devices"]["gripper"]["samples"], 3);
  EXPECT_FALSE(summary.contains("estimate"));
  EXPECT_NE(r.out.find(R"("wrench":[0.0,-3.0,0.0,0.0,0.0,0.0])"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(R"("force":3.0)"), std::string::npos);

  write_text(dir / "bus_off.txt", "0.04 bus_off ft 0.02\n");
  const CommandResult faulted =
      run_pliant("replay --stepped --no-estimate " + quoted(rec.string()) + " --faults " + quoted(dir / "bus_off.txt"));
  ASSERT_EQ(faulted.status, 0) << faulted.err;
  EXPECT_NE(faulted.out.find(R"("device":"wrench","error":"bus_off")"), std::string::npos) << faulted.out;
  EXPECT_EQ(last_json_line(faulted.out)["summary"]["devices"]["wrench"]["bus_off"].get<int>() > 0, true);
}

TEST(CliReplay, RealTimeFollowsTheRecordedClockScaledBySpeed) {
  const auto start = std::chrono::steady_clock::now();
  const CommandResult r = run_pliant("replay --speed 9 --no-estimate " + quoted(kFoamMedium));
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json p = last_json_line(r.out)["summary"]["devices"]["particles"];
  EXPECT_EQ(p["samples"].get<int>() + p["dropped"].get<int>(), 136);
  // 4.5 recorded seconds at 9x: at least 0.5 s (a lower bound only: a loaded machine is slower).
  EXPECT_GE(elapsed, 0.45);
}

TEST(CliReplay, BadScriptsAndOptionsAreRefused) {
  TempDir dir;
  write_text(dir / "bad.txt", "1.0 disconnect observer 0.2\nsoon drop observer 0.1\n");
  CommandResult r = run_pliant("replay --stepped " + quoted(kFoamMedium) + " --faults " + quoted(dir / "bad.txt"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("fault script:2:1:"), std::string::npos) << r.err;

  write_text(dir / "color.txt", "1.0 drop color 0.2\n");
  r = run_pliant("replay --stepped " + quoted(kFoamMedium) + " --faults " + quoted(dir / "color.txt"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("'color' events cannot be replayed"), std::string::npos) << r.err;

  write_text(dir / "ft.txt", "1.0 bus_off ft 0.2\n");
  r = run_pliant("replay --stepped " + quoted(kFoamMedium) + " --faults " + quoted(dir / "ft.txt"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no wrench.csv"), std::string::npos) << r.err;

  write_text(dir / "kind.txt", "1.0 bus_off observer 0.2\n");
  r = run_pliant("replay --stepped " + quoted(kFoamMedium) + " --faults " + quoted(dir / "kind.txt"));
  EXPECT_EQ(r.status, 2);

  r = run_pliant("replay --stepped " + quoted(kFoamMedium) + " --faults " + quoted(dir / "missing.txt"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("cannot read fault script"), std::string::npos);

  r = run_pliant("replay --speed 0 " + quoted(kFoamMedium));
  EXPECT_EQ(r.status, 2);
  for (const char* alpha : {"0", "1.5", "nan", "x"}) {
    r = run_pliant("replay --stepped --msm-alpha " + std::string(alpha) + " " + quoted(kFoamMedium));
    EXPECT_EQ(r.status, 2) << alpha;
  }
  for (const char* iterations : {"-1", "4097", "x"}) {
    r = run_pliant("replay --stepped --settled-row " + std::string(iterations) + " " + quoted(kFoamMedium));
    EXPECT_EQ(r.status, 2) << iterations;
  }
  r = run_pliant("replay --stepped --settled-row 4097 " + quoted(kFoamMedium));
  EXPECT_NE(r.err.find("the quasi-static row takes 0 to 4096 iterations per frame"), std::string::npos) << r.err;
  r = run_pliant("replay --stepped " + quoted(dir / "nothing"));
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.find("Sanitizer"), std::string::npos);
}

}  // namespace
}  // namespace pliant::cli_test
