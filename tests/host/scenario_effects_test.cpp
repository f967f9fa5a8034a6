// Concealed effects, substeps, cluster radius, occlusion and release in simulated recordings.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pliant/host/recording.hpp"
#include "pliant/host/scenarios.hpp"
#include "../support/temp_dir.hpp"

namespace pliant::host {
namespace {

namespace fs = std::filesystem;

ScenarioOptions with_effect(ScenarioOptions options, const std::string& effect) {
  parse_effect_argument(effect, options);
  return options;
}

// Largest coordinate difference between two recordings of the same shape (NaN pairs skipped).
double max_difference(const Recording& a, const Recording& b) {
  EXPECT_EQ(a.positions.size(), b.positions.size());
  double largest = 0.0;
  for (std::size_t k = 0; k < std::min(a.positions.size(), b.positions.size()); ++k) {
    if (std::isnan(a.positions[k]) || std::isnan(b.positions[k])) continue;
    largest = std::max(largest, std::abs(a.positions[k] - b.positions[k]));
  }
  return largest;
}

bool bitwise_equal(const Recording& a, const Recording& b) {
  if (a.positions.size() != b.positions.size() || a.frame_times_s != b.frame_times_s) return false;
  for (std::size_t k = 0; k < a.positions.size(); ++k) {
    const double x = a.positions[k];
    const double y = b.positions[k];
    if (std::isnan(x) != std::isnan(y)) return false;
    if (!std::isnan(x) && x != y) return false;
  }
  return true;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

ScenarioOptions noisy() {
  ScenarioOptions options;
  options.msm_beta = 0.5;
  options.noise = 0.005;
  options.seed = 11;
  return options;
}

TEST(scenario_effects, EveryEffectChangesEveryScenarioAtTheSameSeed) {
  for (const std::string& scenario : scenario_names()) {
    ScenarioOptions options = noisy();
    options.release = true;
    const ScenarioResult plain = make_scenario(scenario, options);
    const double spacing = plain.truth.at("spacing").get<double>();
    for (const std::string& effect : effect_names()) {
      const ScenarioResult changed = make_scenario(scenario, with_effect(options, effect));
      // The smallest default effect (friction on the dome) moves its support by 3e-3 spacings.
      EXPECT_GT(max_difference(plain.recording, changed.recording), 1e-3 * spacing) << scenario << " " << effect;
      // Same noise draws: frame 0 (the still object) is identical.
      for (std::size_t k = 0; k < static_cast<std::size_t>(plain.recording.particle_count * plain.recording.dimension);
           ++k) {
        ASSERT_EQ(plain.recording.positions[k], changed.recording.positions[k]) << scenario << " " << effect;
      }
      EXPECT_EQ(changed.truth.at("effect").get<std::string>(), effect);
    }
  }
}

TEST(scenario_effects, NullValuesReproduceTheRecordingWithoutEffect) {
  const std::vector<std::string> nulls = {"plasticity:creep=0",
                                          "viscosity:fraction=0,damping=0",
                                          "friction:mu=inf",
                                          "gravity:g=0,tilt=30",
                                          "heterogeneity:ratio=1",
                                          "stiffening:k=0",
                                          "heterogeneity:ratio=1,region=left",
                                          "none"};
  for (const std::string& scenario :
       {std::string("foam_press"), std::string("dome_press"), std::string("cantilever_strip")}) {
    ScenarioOptions options = noisy();
    options.substeps = 2;
    options.cluster_radius_factor = 1.8;
    options.occlusion = 0.1;
    const ScenarioResult plain = make_scenario(scenario, options);
    for (const std::string& effect : nulls) {
      const ScenarioResult same = make_scenario(scenario, with_effect(options, effect));
      EXPECT_TRUE(bitwise_equal(plain.recording, same.recording)) << scenario << " " << effect;
    }
  }
}

TEST(scenario_effects, TheRecordingNeverMentionsTheEffect) {
  for (const std::string& effect : effect_names()) {
    test_support::TempDir dir("pliant_effects_");
    ScenarioOptions options = with_effect(noisy(), effect);
    options.occlusion = 0.05;
    write_scenario(make_scenario("ring_squeeze", options), dir.path().string());
    const std::string json = read_text(dir.path() / "recording.json");
    const std::string csv = read_text(dir.path() / "particles.csv");
    for (const std::string& word : {std::string("effect"), std::string("gravity"), effect}) {
      EXPECT_EQ(json.find(word), std::string::npos) << effect << ": recording.json mentions " << word;
      EXPECT_EQ(csv.find(word), std::string::npos) << effect << ": particles.csv mentions " << word;
    }
    const Recording read = read_recording(dir.path().string());
    EXPECT_FALSE(read.gravity.has_value()) << effect;
    const nlohmann::json truth = nlohmann::json::parse(read_text(dir.path() / "truth.json"));
    EXPECT_EQ(truth.at("effect").get<std::string>(), effect);
    EXPECT_FALSE(truth.at("effect_parameters").empty()) << effect;
  }
}

TEST(scenario_effects, GravityActsAlongDownWithoutAGravityKey) {
  ScenarioOptions options = noisy();
  options.noise = 0.0;
  const ScenarioResult plain = make_scenario("cantilever_strip", options);
  const ScenarioResult heavy = make_scenario("cantilever_strip", with_effect(options, "gravity"));
  EXPECT_FALSE(heavy.recording.gravity.has_value());
  // Before the tool moves (t < 0.5 s; it holds the tip from the start) the span already sags,
  // downward (-y), by more than 5 % of the spacing somewhere.
  const Recording& a = plain.recording;
  const Recording& b = heavy.recording;
  const int frame = 29;  // 0.483 s at 60 frames/s
  double lowest = 0.0;
  for (int i = 0; i < a.particle_count; ++i)
    lowest = std::min(lowest, b.position(frame, i, 1) - a.position(frame, i, 1));
  EXPECT_LT(lowest, -0.05 * 0.01);
  const auto gravity = heavy.truth.at("effect_details").at("gravity_vector").get<std::vector<double>>();
  ASSERT_EQ(gravity.size(), 2u);
  EXPECT_EQ(gravity[0], 0.0);
  EXPECT_LT(gravity[1], 0.0);
}

TEST(scenario_effects, DefaultsAndDerivedValuesGoIntoTheTruth) {
  const ScenarioResult result = make_scenario("foam_press", with_effect(noisy(), "plasticity:yield=0.05"));
  const nlohmann::json& parameters = result.truth.at("effect_parameters");
  EXPECT_DOUBLE_EQ(parameters.at("yield").get<double>(), 0.05);
  EXPECT_DOUBLE_EQ(parameters.at("creep").get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(parameters.at("max").get<double>(), 0.5);
  const ScenarioResult friction = make_scenario("foam_press", with_effect(noisy(), "friction"));
  // Image plane: y points down, so into the object from the bottom row is -y.
  EXPECT_EQ(friction.truth.at("effect_details").at("support_normal").get<std::vector<double>>(),
            (std::vector<double>{0.0, -1.0}));
  const ScenarioResult region = make_scenario("block_press", with_effect(noisy(), "heterogeneity:region=right"));
  EXPECT_GT(region.truth.at("effect_details").at("region_clusters").get<int>(), 0);
  EXPECT_EQ(make_scenario("foam_press", noisy()).truth.at("effect").get<std::string>(), "none");
}

TEST(scenario_effects, BadEffectTextsAreRefusedNamingTheValidOnes) {
  struct Bad {
    std::string text;
    std::string mentions;
  };
  const std::vector<Bad> cases = {
      {"plastic", "plasticity, viscosity"},
      {"plasticity:foo=1", "yield, creep, max"},
      {"heterogeneity:region=middle", "inclusion, left, right"},
      {"heterogeneity:region=3", "inclusion, left, right"},
      {"stiffening:k=stiff", "k must be a number"},
      {"gravity:g=-1", "g must be >= 0"},
      {"viscosity:fraction=1", "fraction"},
      {"friction:mu=nan", "mu"},
      {"heterogeneity:ratio=3", "ratio"},
      {"none:x=1", "none"},
  };
  for (const Bad& bad : cases) {
    try {
      ScenarioOptions options = noisy();
      parse_effect_argument(bad.text, options);
      (void)make_scenario("foam_press", options);
      ADD_FAILURE() << bad.text << " was accepted";
    } catch (const std::invalid_argument& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(bad.mentions), std::string::npos) << bad.text << ": " << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
  for (const std::string text : {"", ":mu=1", "friction:", "friction:mu", "friction:=1", "friction:mu=1,mu=2"}) {
    ScenarioOptions options;
    EXPECT_THROW(parse_effect_argument(text, options), std::invalid_argument) << text;
  }
}

TEST(scenario_effects, OcclusionRemovesTheShareAskedInRunsAndSparesFrameZeroAndTheDrivenTool) {
  for (const std::string& scenario : scenario_names()) {
    for (const double share : {0.05, 0.15, 0.4}) {
      ScenarioOptions options = noisy();
      options.occlusion = share;
      options.release = true;
      const ScenarioResult result = make_scenario(scenario, options);
      const Recording& rec = result.recording;
      const int frames = rec.frame_count();
      const int n = rec.particle_count;
      long missing = 0;
      long runs = 0;
      for (int i = 0; i < n; ++i) {
        for (int k = 0; k < frames; ++k) {
          const bool seen = rec.observed(k, i);
          if (!seen) {
            ++missing;
            if (k == 0 || rec.observed(k - 1, i)) ++runs;
          }
          if (k == 0) {
            EXPECT_TRUE(seen) << scenario << " particle " << i;
          }
          for (const DrivenWindow& window : rec.driven) {
            const double t = rec.frame_times_s[static_cast<std::size_t>(k)];
            if (window.id == i && t >= window.from_s && t <= window.to_s) {
              EXPECT_TRUE(seen) << scenario << " driven " << i << " frame " << k;
            }
          }
        }
      }
      const double total = static_cast<double>(frames) * n;
      EXPECT_NEAR(static_cast<double>(missing) / total, share, 0.01) << scenario;
      EXPECT_EQ(result.truth.at("occluded_observations").get<long>(), missing);
      // Contiguous runs (3 frames or more when not cut or merged), not scattered single frames.
      EXPECT_GT(static_cast<double>(missing) / static_cast<double>(runs), 2.0) << scenario;
    }
  }
}

TEST(scenario_effects, OcclusionLeavesTheSeenPositionsAsTheyWere) {
  ScenarioOptions options = noisy();
  const ScenarioResult full = make_scenario("block_press", options);
  options.occlusion = 0.1;
  const ScenarioResult holes = make_scenario("block_press", options);
  EXPECT_EQ(max_difference(full.recording, holes.recording), 0.0);
}

TEST(scenario_effects, SubstepsAndClusterRadiusChangeTheGeneratorAndAreRecorded) {
  const ScenarioResult plain = make_scenario("foam_press", noisy());
  ScenarioOptions options = noisy();
  options.substeps = 2;
  const ScenarioResult finer = make_scenario("foam_press", options);
  EXPECT_GT(max_difference(plain.recording, finer.recording), 0.1);  // px
  EXPECT_EQ(finer.truth.at("steps_per_frame").get<int>(), 2);
  options = noisy();
  // On a square grid 1.5 and 1.8 take the same neighbours (at 1 and 1.41 spacings); 2.2 adds
  // those at 2.
  options.cluster_radius_factor = 2.2;
  const ScenarioResult wider = make_scenario("foam_press", options);
  EXPECT_GT(max_difference(plain.recording, wider.recording), 0.1);
  EXPECT_DOUBLE_EQ(wider.truth.at("cluster_radius_factor").get<double>(), 2.2);
  options.cluster_radius_factor = 1.8;
  EXPECT_GT(
      max_difference(make_scenario("dome_press", noisy()).recording, make_scenario("dome_press", options).recording),
      1e-4);
  options = noisy();
  options.substeps = 1;
  options.cluster_radius_factor = 1.5;
  EXPECT_TRUE(bitwise_equal(plain.recording, make_scenario("foam_press", options).recording));
}

TEST(scenario_effects, ReleaseAndDepthShapeTheToolMotion) {
  ScenarioOptions options = noisy();
  options.noise = 0.0;
  const ScenarioResult held = make_scenario("block_press", options);
  options.release = true;
  const ScenarioResult released = make_scenario("block_press", options);
  ASSERT_EQ(released.recording.driven.size(), 1u);
  EXPECT_DOUBLE_EQ(released.recording.driven[0].to_s, 3.5);
  EXPECT_TRUE(std::isinf(held.recording.driven[0].to_s));
  EXPECT_EQ(released.recording.frame_count(), held.recording.frame_count() + 45);
  // After the release the pressed particle springs back up from 6 mm down.
  const int tool = released.recording.driven[0].id;
  const Recording& r = released.recording;
  const int last = r.frame_count() - 1;
  EXPECT_GT(r.position(last, tool, 2) - r.position(105, tool, 2), 0.002);

  options.depth = 0.1;
  const ScenarioResult shallow = make_scenario("block_press", options);
  EXPECT_NEAR(shallow.recording.position(45, tool, 2) - shallow.recording.position(0, tool, 2), -0.003, 1e-12);
  for (const std::string scenario : {"ring_squeeze", "dome_press"}) {
    const ScenarioResult result = make_scenario(scenario, noisy());
    ASSERT_EQ(result.recording.driven.size(), 1u) << scenario;
    EXPECT_TRUE(std::isfinite(result.recording.driven[0].to_s)) << scenario;
    EXPECT_FALSE(result.recording.fixed.empty()) << scenario;
  }
}

TEST(scenario_effects, OptionsOutOfRangeAreRefused) {
  const std::vector<void (*)(ScenarioOptions&)> breakers = {
      [](ScenarioOptions& o) { o.substeps = 0; },
      [](ScenarioOptions& o) { o.substeps = 65; },
      [](ScenarioOptions& o) { o.cluster_radius_factor = 0.9; },
      [](ScenarioOptions& o) { o.occlusion = 0.6; },
      [](ScenarioOptions& o) { o.occlusion = -0.1; },
      [](ScenarioOptions& o) { o.depth = 2.5; },
      [](ScenarioOptions& o) { o.depth = -1; },
  };
  for (auto breaker : breakers) {
    ScenarioOptions options;
    breaker(options);
    EXPECT_THROW((void)make_scenario("foam_press", options), std::invalid_argument);
  }
}

TEST(scenario_effects, BlockGridSizesTheBlockAndKeepsTheToolOnTheTopCentre) {
  ScenarioOptions options;
  options.noise = 0.0;
  const ScenarioResult standard = make_scenario("block_press", options);
  options.block_grid = {5, 5, 4};
  EXPECT_TRUE(bitwise_equal(standard.recording, make_scenario("block_press", options).recording));
  EXPECT_EQ(standard.recording.particle_count, 100);
  EXPECT_EQ(standard.recording.driven[0].id, 87);

  options.block_grid = {10, 10, 5};
  const ScenarioResult large = make_scenario("block_press", options);
  const Recording& r = large.recording;
  ASSERT_EQ(r.particle_count, 500);
  EXPECT_EQ(r.fixed.size(), 100u);  // the bottom layer
  EXPECT_EQ(r.fixed.back(), 99);
  ASSERT_EQ(r.driven.size(), 1u);
  const int tool = r.driven[0].id;
  EXPECT_EQ(tool, 455);
  EXPECT_NEAR(r.position(0, tool, 0), 0.05, 1e-12);
  EXPECT_NEAR(r.position(0, tool, 1), 0.05, 1e-12);
  EXPECT_NEAR(r.position(0, tool, 2), 0.04, 1e-12);
  // Depth 0.2 of the 40 mm height: 8 mm down once the 1 s press (from 0.5 s) is done.
  EXPECT_NEAR(r.position(45, tool, 2) - r.position(0, tool, 2), -0.008, 1e-12);
  EXPECT_DOUBLE_EQ(large.truth["tool_travel"].get<double>(), 0.2 * 0.04);
  // The inclusion is inside the larger block too.
  ScenarioOptions hetero = options;
  parse_effect_argument("heterogeneity", hetero);
  const ScenarioResult region = make_scenario("block_press", hetero);
  EXPECT_GT(region.truth["effect_details"]["region_clusters"].get<int>(), 0);
}

TEST(scenario_effects, BadBlockGridsAreRefused) {
  for (const ScenarioOptions::BlockGrid grid :
       {ScenarioOptions::BlockGrid{1, 5, 4}, ScenarioOptions::BlockGrid{5, 0, 4}, ScenarioOptions::BlockGrid{5, 5, 1},
        ScenarioOptions::BlockGrid{65, 5, 4}, ScenarioOptions::BlockGrid{5, 5, -3}}) {
    ScenarioOptions options;
    options.block_grid = grid;
    EXPECT_THROW((void)make_scenario("block_press", options), std::invalid_argument)
        << grid.nx << " x " << grid.ny << " x " << grid.nz;
  }
  // A grid other than the default means nothing to the other scenarios: refused, not ignored.
  ScenarioOptions options;
  options.block_grid = {10, 10, 5};
  EXPECT_THROW((void)make_scenario("foam_press", options), std::invalid_argument);
  EXPECT_THROW((void)make_scenario("dome_press", options), std::invalid_argument);
}

}  // namespace
}  // namespace pliant::host
