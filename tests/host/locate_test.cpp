// locate_mismatch and the residual signatures on synthetic fields built to show one signature
// each, on white noise (where every signature must vanish) and on degenerate input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "pliant/host/diagnose/locate.hpp"

namespace pliant::host::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kCols = 6;
constexpr int kRows = 4;
constexpr int kFrames = 120;
constexpr double kRate = 30.0;
constexpr int kTool = 3 * kCols + 3;  // top row, driven
constexpr double kDepth = 0.3;        // press depth, spacing 1

// 2D grid (spacing 1) on a support (row 0 fixed), the top particle kTool pressed kDepth down over
// frames 15..45 and held. `sim` is a smooth deformation; the recording observes it plus white
// noise of std `sigma`; tests add an effect to the observation.
struct Scene {
  Recording rec;
  std::vector<double> sim;
  double sigma = 0.01;

  static double press(int frame) { return kDepth * std::clamp((frame - 15) / 30.0, 0.0, 1.0); }
  static std::size_t index(int frame, int id, int axis) {
    return (static_cast<std::size_t>(frame) * (kCols * kRows) + static_cast<std::size_t>(id)) * 2 +
           static_cast<std::size_t>(axis);
  }
  double& obs(int frame, int id, int axis) { return rec.positions[index(frame, id, axis)]; }
  void add(int frame, int id, double dx, double dy) {
    obs(frame, id, 0) += dx;
    obs(frame, id, 1) += dy;
  }
  double t(int frame) const { return rec.frame_times_s[static_cast<std::size_t>(frame)]; }
  ResidualField field() const { return make_residual_field(rec.positions, sim, rec.particle_count, 2); }
};

// Simulated position of particle (c, r) at a frame, shifted back by `delay` frames.
double sim_y(int c, int r, int frame) {
  return r - Scene::press(frame) * (r / 3.0) * std::exp(-(c - 3) * (c - 3) / 4.0);
}

Scene press_scene(double sigma = 0.01, unsigned seed = 1, int delay_frames = 0) {
  Scene s;
  s.sigma = sigma;
  Recording& rec = s.rec;
  rec.name = "synthetic_press";
  rec.dimension = 2;
  rec.particle_count = kCols * kRows;
  rec.masses.assign(static_cast<std::size_t>(rec.particle_count), 1.0);
  for (int c = 0; c < kCols; ++c) rec.fixed.push_back(c);
  DrivenWindow window;
  window.id = kTool;
  rec.driven.push_back(window);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, sigma);
  for (int k = 0; k < kFrames; ++k) {
    rec.frame_times_s.push_back(k / kRate);
    for (int r = 0; r < kRows; ++r) {
      for (int c = 0; c < kCols; ++c) {
        s.sim.push_back(c);
        s.sim.push_back(sim_y(c, r, k));
        rec.positions.push_back(c + normal(rng));
        rec.positions.push_back(sim_y(c, r, std::max(0, k - delay_frames)) + normal(rng));
      }
    }
  }
  rec.rest_positions.assign(rec.positions.begin(), rec.positions.begin() + 2 * rec.particle_count);
  return s;
}

Location everyone() {
  Location all;
  for (int i = 0; i < kCols * kRows; ++i) all.particles.push_back(i);
  return all;
}

// --- locate_mismatch

TEST(LocateMismatch, FindsParticlesAndWindowOfALocalBump) {
  Scene s = press_scene();
  for (int k = 60; k <= 90; ++k) {
    s.add(k, 14, 0.1, 0.0);
    s.add(k, 15, 0.08, 0.02);
  }
  const Location location = locate_mismatch(s.field(), s.rec.frame_times_s, s.sigma);
  EXPECT_EQ(location.particles, (std::vector<int>{14, 15}));
  // Bridging (2 frames) may join one noise frame next to the bump.
  EXPECT_NEAR(location.t_start, s.t(60), 4.0 / kRate);
  EXPECT_NEAR(location.t_end, s.t(90), 4.0 / kRate);
}

TEST(LocateMismatch, EnergyFractionKeepsTheDominantParticles) {
  Scene s = press_scene();
  for (int k = 0; k < kFrames; ++k) {
    s.add(k, 20, 0.3, 0.0);  // dominant
    s.add(k, 8, 0.03, 0.0);  // clearly above noise, but 1% of the excess energy
  }
  EXPECT_EQ(locate_mismatch(s.field(), s.rec.frame_times_s, s.sigma).particles, (std::vector<int>{20}));
  LocateOptions all_energy;
  all_energy.energy_fraction = 1.0;
  EXPECT_EQ(locate_mismatch(s.field(), s.rec.frame_times_s, s.sigma, all_energy).particles, (std::vector<int>{8, 20}));
}

TEST(LocateMismatch, WhiteNoiseLocatesNothing) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Scene s = press_scene(0.01, seed);
    const Location location = locate_mismatch(s.field(), s.rec.frame_times_s, s.sigma);
    EXPECT_TRUE(location.particles.empty()) << seed;
    EXPECT_EQ(location.t_start, 0.0);
    EXPECT_EQ(location.t_end, 0.0);
  }
}

TEST(LocateMismatch, DegenerateInput) {
  EXPECT_TRUE(locate_mismatch(make_residual_field({}, {}, 5, 2), {}, 0.01).particles.empty());
  EXPECT_TRUE(locate_mismatch(make_residual_field({}, {}, 0, 2), {0.0, 1.0}, 0.01).particles.empty());
  const std::vector<double> blind(8, kNaN);
  EXPECT_TRUE(locate_mismatch(make_residual_field(blind, std::vector<double>(8, 0.0), 1, 2), {0, 1, 2, 3}, 0.01)
                  .particles.empty());
  // Single particle, noise-free, residual in frames 1-2 only.
  const std::vector<double> obs = {0, 0, 1, 0, 1, 0, 0, 0};
  const Location one = locate_mismatch(make_residual_field(obs, std::vector<double>(8, 0.0), 1, 2), {0, 1, 2, 3}, 0.0);
  EXPECT_EQ(one.particles, (std::vector<int>{0}));
  EXPECT_EQ(one.t_start, 1.0);
  EXPECT_EQ(one.t_end, 2.0);
  // All-zero residual without noise: nothing.
  EXPECT_TRUE(locate_mismatch(make_residual_field(obs, obs, 1, 2), {0, 1, 2, 3}, 0.0).particles.empty());
  EXPECT_THROW(locate_mismatch(make_residual_field(obs, obs, 1, 2), {0, 1}, 0.0), std::invalid_argument);
}

// --- persistence_after_unload

TEST(PersistenceAfterUnload, PermanentSetPersistsAndDecayDoesNot) {
  Scene plastic = press_scene();
  Scene elastic = press_scene();
  for (int k = 0; k < kFrames; ++k) {
    const double set = -0.5 * Scene::press(k);  // grows with the load, then stays
    const double decaying = k <= 45 ? set : set * std::exp(-(k - 45) / 5.0);
    for (int id : {14, 15}) {
      plastic.add(k, id, 0.0, set);
      elastic.add(k, id, 0.0, decaying);
    }
  }
  const ResidualField pf = plastic.field();
  const ResidualField ef = elastic.field();
  const Location pl = locate_mismatch(pf, plastic.rec.frame_times_s, plastic.sigma);
  ASSERT_EQ(pl.particles, (std::vector<int>{14, 15}));
  EXPECT_GT(persistence_after_unload(plastic.rec, pf, pl, plastic.sigma), 0.9);
  EXPECT_LT(persistence_after_unload(elastic.rec, ef, pl, elastic.sigma), 0.2);
}

TEST(PersistenceAfterUnload, ReleaseEndsTheLoad) {
  // The driven window ends at frame 70: the residual that stays after it is a permanent set.
  Scene s = press_scene();
  s.rec.driven[0].to_s = s.t(70);
  for (int k = 0; k < kFrames; ++k) {
    const double set = k < 70 ? -0.2 * Scene::press(k) : -0.05;
    for (int id : {14, 15}) s.add(k, id, 0.0, set);
  }
  const ResidualField field = s.field();
  const Location location = locate_mismatch(field, s.rec.frame_times_s, s.sigma);
  // 0.05 / 0.06 without noise; the peak (a maximum over noisy frames) reads ~10% high.
  const double persistence = persistence_after_unload(s.rec, field, location, s.sigma);
  EXPECT_GT(persistence, 0.6);
  EXPECT_LT(persistence, 0.9);
}

TEST(PersistenceAfterUnload, ZeroOnWhiteNoiseAndDegenerate) {
  const Scene s = press_scene();
  const ResidualField field = s.field();
  EXPECT_EQ(persistence_after_unload(s.rec, field, everyone(), s.sigma), 0.0);
  EXPECT_EQ(persistence_after_unload(s.rec, field, Location{}, s.sigma), 0.0);
  Location one;
  one.particles = {9};
  EXPECT_EQ(persistence_after_unload(s.rec, field, one, s.sigma), 0.0);
  Location bad;
  bad.particles = {99};
  EXPECT_THROW(persistence_after_unload(s.rec, field, bad, s.sigma), std::invalid_argument);
}

// --- velocity_correlation

TEST(VelocityCorrelation, ResidualProportionalToDriverVelocity) {
  Scene s = press_scene();
  // Driver velocity is -0.3 / s while pressing; the residual lags behind it like a delay of 0.5 s.
  for (int k = 0; k < kFrames; ++k) {
    const double v = (Scene::press(k + 1) - Scene::press(k - 1)) * kRate / 2.0;
    for (int id : {14, 15}) s.add(k, id, 0.0, -0.5 * v);
  }
  const ResidualField field = s.field();
  const Location location = locate_mismatch(field, s.rec.frame_times_s, s.sigma);
  ASSERT_FALSE(location.particles.empty());
  EXPECT_GT(velocity_correlation(s.rec, field, location), 0.6);

  Scene plastic = press_scene();
  for (int k = 0; k < kFrames; ++k) {
    for (int id : {14, 15}) plastic.add(k, id, 0.0, -0.5 * Scene::press(k));
  }
  const ResidualField pf = plastic.field();
  EXPECT_LT(velocity_correlation(plastic.rec, pf, locate_mismatch(pf, plastic.rec.frame_times_s, plastic.sigma)),
            velocity_correlation(s.rec, field, location));
}

TEST(VelocityCorrelation, ZeroOnWhiteNoiseAndDegenerate) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Scene s = press_scene(0.01, seed);
    EXPECT_EQ(velocity_correlation(s.rec, s.field(), everyone()), 0.0) << seed;
  }
  Scene undriven = press_scene();
  undriven.rec.driven.clear();
  EXPECT_EQ(velocity_correlation(undriven.rec, undriven.field(), everyone()), 0.0);
}

// --- support_motion

TEST(SupportMotion, SlidingSupportIsSeen) {
  Scene s = press_scene();
  for (int k = 0; k < kFrames; ++k) {
    for (int c = 0; c < kCols; ++c) s.add(k, c, 0.05 * Scene::press(k) / kDepth, 0.0);
  }
  const double motion = support_motion(s.rec, s.sigma);
  // Per-axis rms of the slide about the rest is about 3.5 noise std (x only; divided over 2 axes).
  EXPECT_GT(motion, 2.0);
  EXPECT_LT(motion, 5.0);
}

TEST(SupportMotion, ZeroOnWhiteNoiseAndWithoutSupport) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    EXPECT_EQ(support_motion(press_scene(0.01, seed).rec, 0.01), 0.0) << seed;
  }
  Scene s = press_scene();
  s.rec.fixed.clear();
  EXPECT_EQ(support_motion(s.rec, s.sigma), 0.0);
}

// --- uniform_drift

TEST(UniformDrift, SagGrowingWithHeightAlongOneDirection) {
  Scene s = press_scene();
  for (int k = 0; k < kFrames; ++k) {
    for (int r = 0; r < kRows; ++r) {
      for (int c = 0; c < kCols; ++c) s.add(k, r * kCols + c, 0.0, -0.02 * r);
    }
  }
  const UniformDrift drift = uniform_drift(s.rec, s.field(), s.sigma);
  EXPECT_GT(drift.fraction, 0.85);
  ASSERT_EQ(drift.direction.size(), 2u);
  EXPECT_NEAR(drift.direction[0], 0.0, 0.05);
  EXPECT_NEAR(drift.direction[1], -1.0, 0.05);
}

TEST(UniformDrift, LocalBumpIsNotADrift) {
  Scene s = press_scene();
  for (int k = 60; k <= 90; ++k) s.add(k, 14, 0.1, 0.0);
  EXPECT_LT(uniform_drift(s.rec, s.field(), s.sigma).fraction, 0.3);
}

TEST(UniformDrift, ZeroOnWhiteNoiseAndDegenerate) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Scene s = press_scene(0.01, seed);
    const UniformDrift drift = uniform_drift(s.rec, s.field(), s.sigma);
    EXPECT_LT(drift.fraction, 0.05) << seed;
  }
  Scene unsupported = press_scene();
  unsupported.rec.fixed.clear();
  unsupported.rec.driven.clear();
  const UniformDrift none = uniform_drift(unsupported.rec, unsupported.field(), 0.01);
  EXPECT_EQ(none.fraction, 0.0);
  EXPECT_EQ(none.direction, (std::vector<double>{0.0, 0.0}));
}

// --- load_sign_change

TEST(LoadSignChange, ResidualFlipsBetweenSmallAndLargeLoad) {
  Scene stiffening = press_scene();
  Scene linear = press_scene();
  for (int k = 0; k < kFrames; ++k) {
    const double a = Scene::press(k);
    // Along the load direction (0, -1): negative at small load, positive at large load.
    const double along = a * (a - 0.6 * kDepth) / kDepth;
    for (int id : {14, 15}) {
      stiffening.add(k, id, 0.0, -along);
      linear.add(k, id, 0.0, -0.3 * a);
    }
  }
  const ResidualField sf = stiffening.field();
  const Location sl = locate_mismatch(sf, stiffening.rec.frame_times_s, stiffening.sigma);
  ASSERT_FALSE(sl.particles.empty());
  EXPECT_GT(load_sign_change(stiffening.rec, sf, sl, stiffening.sigma), 0.05);
  const ResidualField lf = linear.field();
  const Location ll = locate_mismatch(lf, linear.rec.frame_times_s, linear.sigma);
  ASSERT_FALSE(ll.particles.empty());
  EXPECT_EQ(load_sign_change(linear.rec, lf, ll, linear.sigma), 0.0);
}

TEST(LoadSignChange, ZeroOnWhiteNoiseAndDegenerate) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Scene s = press_scene(0.01, seed);
    EXPECT_EQ(load_sign_change(s.rec, s.field(), everyone(), s.sigma), 0.0) << seed;
  }
  Scene undriven = press_scene();
  undriven.rec.driven.clear();
  EXPECT_EQ(load_sign_change(undriven.rec, undriven.field(), everyone(), 0.01), 0.0);
}

// --- time_shift

TEST(TimeShift, FindsTheDelayOfTheObservation) {
  const Scene s = press_scene(0.002, 1, 3);
  const ResidualField field = s.field();
  const Location location = locate_mismatch(field, s.rec.frame_times_s, s.sigma);
  ASSERT_FALSE(location.particles.empty());
  EXPECT_NEAR(time_shift(s.rec, s.sim, location, s.sigma), 3.0 / kRate, 0.5 / kRate);
  EXPECT_NEAR(time_shift(s.rec, s.sim, Location{}, s.sigma), 3.0 / kRate, 0.5 / kRate);  // driven particle
}

TEST(TimeShift, NoShiftOnWhiteNoiseAndDegenerate) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Scene s = press_scene(0.01, seed);
    EXPECT_LT(std::abs(time_shift(s.rec, s.sim, Location{}, s.sigma)), 0.5 / kRate) << seed;
    EXPECT_LT(std::abs(time_shift(s.rec, s.sim, everyone(), s.sigma)), 0.5 / kRate) << seed;
  }
  Scene still = press_scene();
  const std::vector<double> frozen(still.sim.size(), 1.0);
  EXPECT_EQ(time_shift(still.rec, frozen, Location{}, still.sigma), 0.0);  // no simulated motion
  EXPECT_THROW(time_shift(still.rec, std::vector<double>(3, 0.0), Location{}, still.sigma), std::invalid_argument);
}

// --- all signatures together

void expect_finite(const std::map<std::string, double>& signatures) {
  for (const auto& [name, value] : signatures) EXPECT_TRUE(std::isfinite(value)) << name;
}

TEST(ResidualSignatures, AllKeysFiniteAndZeroOnWhiteNoise) {
  const Scene s = press_scene();
  const std::map<std::string, double> signatures = residual_signatures(s.rec, s.sim, s.sigma);
  for (const char* key : {"persistence_after_unload", "velocity_correlation", "support_motion", "uniform_drift",
                          "uniform_drift_x", "uniform_drift_y", "load_sign_change", "time_shift"}) {
    ASSERT_EQ(signatures.count(key), 1u) << key;
    EXPECT_LT(std::abs(signatures.at(key)), 0.05) << key;
  }
  EXPECT_EQ(signatures.count("uniform_drift_z"), 0u);
}

Recording tiny_recording(int frames, int particles, int dimension, double value) {
  Recording rec;
  rec.dimension = dimension;
  rec.particle_count = particles;
  for (int k = 0; k < frames; ++k) rec.frame_times_s.push_back(k * 0.1);
  rec.positions.assign(static_cast<std::size_t>(frames * particles * dimension), value);
  if (particles > 0) {
    rec.fixed.push_back(0);
    DrivenWindow window;
    window.id = particles - 1;
    rec.driven.push_back(window);
  }
  return rec;
}

TEST(ResidualSignatures, DegenerateRecordings) {
  struct Case {
    int frames, particles, dimension;
    double value;
  };
  for (const Case c : {Case{0, 4, 2, 0.0}, Case{0, 0, 3, 0.0}, Case{1, 1, 3, 0.5}, Case{2, 1, 2, 0.5},
                       Case{5, 3, 3, kNaN}, Case{30, 1, 2, 1.0}}) {
    const Recording rec = tiny_recording(c.frames, c.particles, c.dimension, c.value);
    std::vector<double> sim(rec.positions.size(), 0.25);
    for (double noise : {0.0, 0.01}) {
      std::map<std::string, double> signatures;
      ASSERT_NO_THROW(signatures = residual_signatures(rec, sim, noise)) << c.frames << " " << c.particles;
      expect_finite(signatures);
      EXPECT_EQ(signatures.count("time_shift"), 1u);
    }
  }
  // 3D names the third direction component.
  const Recording rec3 = tiny_recording(10, 4, 3, 1.0);
  EXPECT_EQ(residual_signatures(rec3, rec3.positions, 0.01).count("uniform_drift_z"), 1u);
}

}  // namespace
}  // namespace pliant::host::test
