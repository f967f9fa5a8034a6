// Help, version and usage errors: exit statuses and one-line messages.
#include <gtest/gtest.h>

#include "cli_test_support.hpp"
#include "pliant/host/scenarios.hpp"

namespace pliant::cli_test {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(cli_usage, HelpListsCommandsAndExitsZero) {
  const CommandResult r = run_pliant("--help");
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(contains(r.out, "Usage: pliant")) << r.out;
  EXPECT_TRUE(contains(r.out, "estimate")) << r.out;
  EXPECT_TRUE(contains(r.out, "simulate")) << r.out;
  EXPECT_EQ(r.err, "");
}

TEST(cli_usage, VersionIsTheProjectVersion) {
  const CommandResult r = run_pliant("--version");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out, std::string("pliant ") + PLIANT_VERSION + "\n");
}

TEST(cli_usage, NoCommandPrintsHelpAndExitsTwo) {
  const CommandResult r = run_pliant("");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "Usage: pliant")) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST(cli_usage, UnknownCommandIsOneLineAndExitsTwo) {
  const CommandResult r = run_pliant("frobnicate");
  EXPECT_EQ(r.status, 2);
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_TRUE(contains(r.err, "pliant: ")) << r.err;
  EXPECT_TRUE(contains(r.err, "unknown command 'frobnicate'")) << r.err;
}

TEST(cli_usage, UnknownOptionIsOneLineAndExitsTwo) {
  const CommandResult r = run_pliant("--frobnicate");
  EXPECT_EQ(r.status, 2);
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_TRUE(contains(r.err, "--frobnicate")) << r.err;
}

TEST(cli_usage, CommandHelpShowsItsOptions) {
  const CommandResult estimate = run_pliant("estimate --help");
  EXPECT_EQ(estimate.status, 0);
  for (const char* option :
       {"--json", "--mode", "--alpha", "--msm-alpha", "--steps-per-frame", "--cluster-radius", "--grid", "--quiet"}) {
    EXPECT_TRUE(contains(estimate.out, option)) << option;
  }
  const CommandResult diagnose = run_pliant("diagnose --help");
  EXPECT_EQ(diagnose.status, 0);
  for (const char* option : {"--json", "--report", "--model", "--alpha", "--msm-alpha", "--steps-per-frame",
                             "--cluster-radius", "--quiet"}) {
    EXPECT_TRUE(contains(diagnose.out, option)) << option;
  }
  const CommandResult simulate = run_pliant("simulate --help");
  EXPECT_EQ(simulate.status, 0);
  for (const char* option : {"--output", "--beta", "--alpha", "--noise", "--seed", "--rate", "--force"}) {
    EXPECT_TRUE(contains(simulate.out, option)) << option;
  }
  for (const std::string& name : host::scenario_names()) EXPECT_TRUE(contains(simulate.out, name)) << name;
}

TEST(cli_usage, MissingRecordingArgumentExitsTwo) {
  const CommandResult r = run_pliant("estimate");
  EXPECT_EQ(r.status, 2);
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_TRUE(contains(r.err, "pliant estimate: ")) << r.err;
  EXPECT_TRUE(contains(r.err, "REC")) << r.err;
}

struct BadOption {
  std::string arguments;  // after `estimate REC`
  std::string mentions;
};

TEST(cli_usage, BadEstimateOptionValuesExitTwoWithOneLine) {
  TempDir dir;
  write_tiny_recording(dir / "rec");
  const std::vector<BadOption> cases = {
      {"--mode sideways", "--mode"},
      {"--grid 2", "--grid"},
      {"--grid many", "--grid"},
      {"--msm-alpha 0", "--msm-alpha"},
      {"--msm-alpha 1.5", "--msm-alpha"},
      {"--alpha --mode final", "--alpha"},
      {"--alpha --msm-alpha 0.5", "--alpha"},
      {"--alpha sometimes", "--alpha"},
      {"--alpha fixed=0", "--alpha"},
      {"--alpha fixed=2", "--alpha"},
      {"--alpha fixed=x", "--alpha"},
      {"--alpha fit --mode final", "--alpha"},
      {"--steps-per-frame 0", "--steps-per-frame"},
      {"--steps-per-frame 65", "--steps-per-frame"},
      {"--steps-per-frame 2.5", "--steps-per-frame"},
      {"--steps-per-frame many", "--steps-per-frame"},
      {"--steps-per-frame -1", "--steps-per-frame"},
      {"--cluster-radius 0.9", "--cluster-radius"},
      {"--cluster-radius 4.5", "--cluster-radius"},
      {"--cluster-radius nan", "--cluster-radius"},
      {"--cluster-radius wide", "--cluster-radius"},
      {"--cluster-radius 1.5x", "--cluster-radius"},
  };
  for (const BadOption& c : cases) {
    const CommandResult r = run_pliant("estimate " + quoted(dir / "rec") + " " + c.arguments);
    EXPECT_EQ(r.status, 2) << c.arguments;
    ASSERT_EQ(r.err_lines().size(), 1u) << c.arguments << ": " << r.err;
    EXPECT_EQ(r.err.rfind("pliant estimate: ", 0), 0u) << r.err;
    EXPECT_TRUE(contains(r.err, c.mentions)) << c.arguments << ": " << r.err;
    EXPECT_EQ(r.out, "") << c.arguments;
  }
}

// diagnose takes the same model-form options, with the same refusals, and refuses them with
// the FEM baseline, which has no such form.
TEST(cli_usage, BadDiagnoseModelFormOptionsExitTwoWithOneLine) {
  TempDir dir;
  write_tiny_recording(dir / "rec");
  const std::vector<BadOption> cases = {
      {"--msm-alpha 1.5", "--msm-alpha"},
      {"--alpha --msm-alpha 0.5", "--alpha"},
      {"--alpha sometimes", "--alpha"},
      {"--alpha fixed=0", "--alpha"},
      {"--steps-per-frame 65", "--steps-per-frame"},
      {"--steps-per-frame many", "--steps-per-frame"},
      {"--cluster-radius 0.9", "--cluster-radius"},
      {"--cluster-radius wide", "--cluster-radius"},
      {"--model fem --alpha fit", "--model fem"},
      {"--model fem --cluster-radius 2", "--model fem"},
  };
  const std::string out = dir / "out.json";
  for (const BadOption& c : cases) {
    const CommandResult r =
        run_pliant("diagnose " + quoted(dir / "rec") + " -q --json " + quoted(out) + " " + c.arguments);
    EXPECT_EQ(r.status, 2) << c.arguments;
    ASSERT_EQ(r.err_lines().size(), 1u) << c.arguments << ": " << r.err;
    EXPECT_EQ(r.err.rfind("pliant diagnose: ", 0), 0u) << r.err;
    EXPECT_TRUE(contains(r.err, c.mentions)) << c.arguments << ": " << r.err;
    EXPECT_EQ(r.out, "") << c.arguments;
    EXPECT_FALSE(fs::exists(out)) << c.arguments;
  }
}

}  // namespace
}  // namespace pliant::cli_test
