// ResidualField: construction, NaN propagation, per-particle and per-frame rms, magnitude map.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "pliant/host/diagnose/residual_field.hpp"

namespace pliant::host::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
using Mask = std::vector<unsigned char>;

// 2 frames x 3 particles, 2D. Residuals: frame 0 (3,4) (0,0) unobserved-sim;
// frame 1 (0,0) unobserved-obs (6,8).
ResidualField sample_field() {
  const std::vector<double> obs = {3, 4, 1, 1, 0, 0, /**/ 2, 2, kNaN, 0, 7, 9};
  const std::vector<double> sim = {0, 0, 1, 1, kNaN, 0, /**/ 2, 2, 0, 0, 1, 1};
  return make_residual_field(obs, sim, 3, 2);
}

TEST(ResidualField, ResidualIsObservedMinusSimulatedWithNaNPairs) {
  const ResidualField field = sample_field();
  EXPECT_EQ(field.frame_count, 2);
  EXPECT_EQ(field.particle_count, 3);
  EXPECT_EQ(field.at(0, 0)[0], 3.0);
  EXPECT_EQ(field.at(0, 0)[1], 4.0);
  EXPECT_TRUE(field.observed(0, 1));
  EXPECT_FALSE(field.observed(0, 2));
  EXPECT_TRUE(std::isnan(field.at(0, 2)[1]));  // the finite coordinate is NaN as well
  EXPECT_FALSE(field.observed(1, 1));
  EXPECT_DOUBLE_EQ(field.squared_norm(1, 2), 100.0);
  EXPECT_TRUE(std::isnan(field.squared_norm(0, 2)));
}

TEST(ResidualField, ParticleAndFrameRms) {
  const ResidualField field = sample_field();
  const std::vector<double> by_particle = particle_rms(field);
  ASSERT_EQ(by_particle.size(), 3u);
  EXPECT_DOUBLE_EQ(by_particle[0], std::sqrt(12.5));
  EXPECT_DOUBLE_EQ(by_particle[1], 0.0);
  EXPECT_DOUBLE_EQ(by_particle[2], 10.0);
  EXPECT_EQ(particle_samples(field), (std::vector<int>{2, 1, 1}));
  const Mask first_frame = {1, 0};
  EXPECT_DOUBLE_EQ(particle_rms(field, &first_frame)[0], 5.0);
  EXPECT_EQ(particle_samples(field, &first_frame), (std::vector<int>{1, 1, 0}));

  const std::vector<double> by_frame = frame_rms(field);
  ASSERT_EQ(by_frame.size(), 2u);
  EXPECT_DOUBLE_EQ(by_frame[0], std::sqrt(12.5));
  EXPECT_DOUBLE_EQ(by_frame[1], std::sqrt(50.0));
  EXPECT_EQ(frame_samples(field), (std::vector<int>{2, 2}));
  const Mask only_two = {0, 0, 1};
  EXPECT_EQ(frame_rms(field, &only_two), (std::vector<double>{0.0, 10.0}));
  EXPECT_EQ(frame_samples(field, &only_two), (std::vector<int>{0, 1}));
}

TEST(ResidualField, MagnitudeMapIsFrameMajorWithNaN) {
  const std::vector<double> map = residual_magnitudes(sample_field());
  ASSERT_EQ(map.size(), 6u);
  EXPECT_DOUBLE_EQ(map[0], 5.0);
  EXPECT_DOUBLE_EQ(map[1], 0.0);
  EXPECT_TRUE(std::isnan(map[2]));
  EXPECT_DOUBLE_EQ(map[3], 0.0);
  EXPECT_TRUE(std::isnan(map[4]));
  EXPECT_DOUBLE_EQ(map[5], 10.0);
}

TEST(ResidualField, DegenerateInput) {
  const ResidualField empty = make_residual_field({}, {}, 4, 3);
  EXPECT_EQ(empty.frame_count, 0);
  EXPECT_TRUE(particle_rms(empty) == std::vector<double>(4, 0.0));
  EXPECT_TRUE(frame_rms(empty).empty());
  EXPECT_TRUE(residual_magnitudes(empty).empty());

  const ResidualField none = make_residual_field({}, {}, 0, 2);
  EXPECT_EQ(none.frame_count, 0);
  EXPECT_TRUE(particle_rms(none).empty());

  const std::vector<double> blind(6, kNaN);
  const ResidualField all_nan = make_residual_field(blind, std::vector<double>(6, 0.0), 1, 3);
  EXPECT_EQ(all_nan.frame_count, 2);
  EXPECT_EQ(particle_rms(all_nan), (std::vector<double>{0.0}));
  EXPECT_EQ(frame_rms(all_nan), (std::vector<double>{0.0, 0.0}));
  EXPECT_EQ(particle_samples(all_nan), (std::vector<int>{0}));
}

TEST(ResidualField, RejectsInconsistentInput) {
  EXPECT_THROW(make_residual_field({1, 2, 3}, {1, 2}, 1, 1), std::invalid_argument);
  EXPECT_THROW(make_residual_field({1, 2, 3}, {1, 2, 3}, 1, 2), std::invalid_argument);
  EXPECT_THROW(make_residual_field({1, 2}, {1, 2}, 0, 2), std::invalid_argument);
  EXPECT_THROW(make_residual_field({1, 2}, {1, 2}, 1, 0), std::invalid_argument);
  const ResidualField field = sample_field();
  const Mask wrong = {1};
  EXPECT_THROW(particle_rms(field, &wrong), std::invalid_argument);
  EXPECT_THROW(frame_rms(field, &wrong), std::invalid_argument);
}

}  // namespace
}  // namespace pliant::host::test
