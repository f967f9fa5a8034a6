// estimate_noise_std: accuracy on simulated scenarios with known noise, robustness to missing
// fixed particles, occlusion and uneven timestamps, and degenerate recordings.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "pliant/host/diagnose/noise_floor.hpp"
#include "pliant/host/scenarios.hpp"

namespace pliant::host::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kTwoPi = 6.283185307179586;

ScenarioResult scenario(const std::string& name, double noise, std::uint64_t seed = 1) {
  ScenarioOptions options;
  options.noise = noise;
  options.seed = seed;
  return make_scenario(name, options);
}

// Keeps frame k when keep(k), rebuilding times and positions.
template <typename Keep>
Recording keep_frames(const Recording& in, Keep keep) {
  Recording out = in;
  out.frame_times_s.clear();
  out.positions.clear();
  const std::size_t stride = static_cast<std::size_t>(in.particle_count * in.dimension);
  for (int k = 0; k < in.frame_count(); ++k) {
    if (!keep(k)) continue;
    out.frame_times_s.push_back(in.frame_times_s[static_cast<std::size_t>(k)]);
    const auto first = in.positions.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(k) * stride);
    out.positions.insert(out.positions.end(), first, first + static_cast<std::ptrdiff_t>(stride));
  }
  return out;
}

void hide_particle(Recording& recording, int id) {
  for (int k = 0; k < recording.frame_count(); ++k) {
    for (int d = 0; d < recording.dimension; ++d) {
      recording.positions[(static_cast<std::size_t>(k) * static_cast<std::size_t>(recording.particle_count) +
                           static_cast<std::size_t>(id)) *
                              static_cast<std::size_t>(recording.dimension) +
                          static_cast<std::size_t>(d)] = kNaN;
    }
  }
}

TEST(NoiseFloor, WithinQuarterOfTruthOnEveryScenario) {
  for (const std::string& name : scenario_names()) {
    for (double noise : {0.002, 0.005, 0.02}) {
      const ScenarioResult s = scenario(name, noise);
      const double truth = s.truth["noise_std"].get<double>();
      const double estimate = estimate_noise_std(s.recording);
      std::cout << "[noise] " << name << " noise=" << noise << " estimate/truth=" << estimate / truth << "\n";
      EXPECT_NEAR(estimate / truth, 1.0, 0.25) << name << " noise " << noise;
    }
  }
}

TEST(NoiseFloor, NoiseFreeScenariosAreFarBelowSpacing) {
  for (const std::string& name : scenario_names()) {
    const ScenarioResult s = scenario(name, 0.0);
    const double spacing = s.truth["spacing"].get<double>();
    const double estimate = estimate_noise_std(s.recording);
    std::cout << "[noise] " << name << " noise=0 estimate/spacing=" << estimate / spacing << "\n";
    EXPECT_GE(estimate, 0.0);
    EXPECT_LT(estimate, 1e-4 * spacing) << name;
  }
}

TEST(NoiseFloor, NeedsNoFixedParticlesNorStillLeadIn) {
  for (const std::string& name : scenario_names()) {
    ScenarioResult s = scenario(name, 0.005, 3);
    Recording& rec = s.recording;
    for (int id : rec.fixed) hide_particle(rec, id);
    rec.fixed.clear();
    // Drop the 0.5 s lead-in at rest, so every remaining track is moving.
    const Recording moving =
        keep_frames(rec, [&](int k) { return rec.frame_times_s[static_cast<std::size_t>(k)] > 0.55; });
    const double truth = s.truth["noise_std"].get<double>();
    const double ratio = estimate_noise_std(moving) / truth;
    std::cout << "[noise] " << name << " moving tracks only estimate/truth=" << ratio << "\n";
    EXPECT_NEAR(ratio, 1.0, 0.25) << name;
  }
}

TEST(NoiseFloor, OcclusionAndUnevenTimestamps) {
  for (const std::string& name : scenario_names()) {
    ScenarioResult s = scenario(name, 0.005, 5);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    // 30% of frames dropped (uneven timestamps), then 20% of the samples occluded.
    Recording rec = keep_frames(s.recording, [&](int k) { return k == 0 || uniform(rng) > 0.3; });
    const std::size_t stride = static_cast<std::size_t>(rec.dimension);
    for (std::size_t start = 0; start < rec.positions.size(); start += stride) {
      if (uniform(rng) < 0.2) {
        for (std::size_t d = 0; d < stride; ++d) rec.positions[start + d] = kNaN;
      }
    }
    const double truth = s.truth["noise_std"].get<double>();
    const double ratio = estimate_noise_std(rec) / truth;
    std::cout << "[noise] " << name << " occluded + uneven estimate/truth=" << ratio << "\n";
    EXPECT_NEAR(ratio, 1.0, 0.25) << name;
  }
}

TEST(NoiseFloor, JitteredTimestampsOfASwingingParticle) {
  // One particle, no support: a 1.5 Hz swing sampled at 60 Hz with jittered sample times.
  std::mt19937 rng(2);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> jitter(-0.004, 0.004);
  Recording rec;
  rec.dimension = 2;
  rec.particle_count = 1;
  const double sigma = 1e-4;
  for (int k = 0; k < 240; ++k) {
    const double t = k / 60.0 + jitter(rng);
    rec.frame_times_s.push_back(t);
    rec.positions.push_back(0.02 * std::sin(kTwoPi * 1.5 * t) + sigma * normal(rng));
    rec.positions.push_back(-0.005 * std::cos(kTwoPi * 1.5 * t) + sigma * normal(rng));
  }
  EXPECT_NEAR(estimate_noise_std(rec) / sigma, 1.0, 0.25);
}

TEST(NoiseFloor, DegenerateRecordingsGiveZero) {
  ScenarioResult s = scenario("foam_press", 0.01);
  for (int frames : {0, 1, 2}) {
    const Recording few = keep_frames(s.recording, [&](int k) { return k < frames; });
    const double estimate = estimate_noise_std(few);
    EXPECT_EQ(estimate, 0.0) << frames << " frames";
  }
  Recording blind = s.recording;
  for (double& p : blind.positions) p = kNaN;
  EXPECT_EQ(estimate_noise_std(blind), 0.0);

  Recording empty;
  empty.particle_count = 0;
  EXPECT_EQ(estimate_noise_std(empty), 0.0);

  // Three frames: a linear fit through three samples still measures something finite.
  const Recording three = keep_frames(s.recording, [](int k) { return k < 3; });
  EXPECT_TRUE(std::isfinite(estimate_noise_std(three)));
}

TEST(NoiseFloor, RejectsInconsistentRecording) {
  ScenarioResult s = scenario("foam_press", 0.01);
  s.recording.positions.pop_back();
  EXPECT_THROW(estimate_noise_std(s.recording), std::invalid_argument);
}

}  // namespace
}  // namespace pliant::host::test
