// The simulated grasp: its shapes, its ground-truth strain against an SVD oracle, its
// quasi-static squeeze against the grasp guard's own prediction at the same msm_beta, the
// force law, release, and bounded catch-up.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "hal_fixture.hpp"
#include "pliant/core/grasp_guard.hpp"

namespace pliant::hal {
namespace {

using test::SteppedClock;

TEST(HalSimulatedGrasp, BuildsEachShapeAndRefusesBadConfigurations) {
  SteppedClock t;
  SimulatedGrasp plant(t.clock);
  SimulatedGraspConfig c = test::small_grasp();
  ASSERT_EQ(plant.configure(c), HalStatus::ok);
  EXPECT_EQ(plant.particle_count(), 60);
  EXPECT_NEAR(plant.extent_m(), 0.032, 1e-12);
  c.object.shape = ObjectShape::cylinder;
  c.object.nx = 2;
  c.object.nz = 3;
  ASSERT_EQ(plant.configure(c), HalStatus::ok);
  EXPECT_EQ(plant.particle_count(), 13 * 3);
  c.object.shape = ObjectShape::ball;
  ASSERT_EQ(plant.configure(c), HalStatus::ok);
  EXPECT_EQ(plant.particle_count(), 33);
  EXPECT_NEAR(plant.extent_m(), 0.032, 1e-12);

  auto refused = [&](auto mutate) {
    SimulatedGraspConfig bad = test::small_grasp();
    mutate(bad);
    SimulatedGrasp p(t.clock);
    return p.configure(bad) == HalStatus::invalid_argument && !p.configured();
  };
  EXPECT_TRUE(refused([](SimulatedGraspConfig& b) { b.object.msm_beta = 1.5; }));
  EXPECT_TRUE(refused([](SimulatedGraspConfig& b) { b.object.spacing_m = 0; }));
  EXPECT_TRUE(refused([](SimulatedGraspConfig& b) { b.object.nx = 1; }));
  EXPECT_TRUE(refused([](SimulatedGraspConfig& b) { b.object.stiffness_n_per_m = -1; }));
  EXPECT_TRUE(refused([](SimulatedGraspConfig& b) { b.object.stiffening = std::nan(""); }));
  EXPECT_TRUE(refused([](SimulatedGraspConfig& b) { b.period_s = 0; }));
  EXPECT_TRUE(refused([](SimulatedGraspConfig& b) { b.max_steps_per_period = 0; }));
  EXPECT_TRUE(refused([](SimulatedGraspConfig& b) { b.max_width_m = 0.03; }));  // narrower than the object
  EXPECT_TRUE(refused([](SimulatedGraspConfig& b) { b.initial_width_m = 0.2; }));
  EXPECT_TRUE(refused([](SimulatedGraspConfig& b) { b.max_closure_fraction = 1; }));
  EXPECT_TRUE(refused([](SimulatedGraspConfig& b) {
    b.object.shape = ObjectShape::ball;
    b.object.nx = 1;  // 7 particles
  }));
}

// Ground truth against Eigen's SVD on known affine maps x = R F rest + t.
TEST(HalSimulatedGrasp, TrueStrainMatchesSvdOfKnownDeformations) {
  SteppedClock t;
  SimulatedGrasp plant(t.clock);
  ASSERT_EQ(plant.configure(test::small_grasp()), HalStatus::ok);
  const int n = plant.particle_count();
  EXPECT_NEAR(plant.max_strain(plant.rest_positions()), 0.0, 1e-12);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::Matrix3d maps[3];
  maps[0] = Eigen::Vector3d(0.95, 1.0, 1.0).asDiagonal();
  maps[1] << 1.02, 0.03, 0, 0.01, 0.97, 0.02, 0, 0.04, 1.05;
  maps[2] = Eigen::Matrix3d::Identity();
  for (const Eigen::Matrix3d& f : maps) {
    std::vector<Eigen::Vector3d> x(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
      x[static_cast<std::size_t>(i)] = rotation * f * plant.rest_positions()[i] + Eigen::Vector3d(0.1, -0.2, 0.3);
    // A dynamic-size SVD (GCC 12 warns falsely on the fixed-size one's members).
    const Eigen::MatrixXd dynamic = f;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(dynamic);
    const double expected = (svd.singularValues().array() - 1.0).abs().maxCoeff();
    EXPECT_NEAR(plant.max_strain(x.data()), expected, 1e-9);
  }
}

// The jaws held at a closure until the object settles.
struct HeldSqueeze {
  SteppedClock t;
  SimulatedGrasp plant{t.clock};
  HeldSqueeze(double beta, double closure_m) {
    EXPECT_EQ(plant.configure(test::small_grasp(beta)), HalStatus::ok);
    plant.command_move(plant.extent_m() - closure_m, 0.002, std::numeric_limits<double>::infinity());
    for (int k = 0; k < 4000 && (plant.moving() || k < 3000); ++k) {
      t.step();
      plant.sync();
    }
  }
};

// The plant and the guard's prediction squeeze the same MSM model by the same contact rule;
// the plant loads continuously, the guard in table steps, so at a tabulated closure they agree
// to within a few per cent.
TEST(HalSimulatedGrasp, SettledSqueezeMatchesTheGuardsPrediction) {
  const double beta = 0.5;
  const double closure = 0.00088;
  HeldSqueeze held(beta, closure);
  SimulatedGrasp* plant = &held.plant;
  const double strain = plant->true_max_strain();
  EXPECT_FALSE(plant->moving());
  EXPECT_GT(plant->contact_count(), 0);
  EXPECT_NEAR(plant->closure_m(), closure, 1e-12);
  std::vector<int> all(static_cast<std::size_t>(plant->particle_count()));
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  GraspGuardConfig config;
  config.max_strain = 0.1;
  config.prediction_max_closure_m = 0.00704;  // closure step 0.22 mm: 0.88 mm is on the grid
  std::vector<unsigned char> block(grasp_guard_workspace_size(plant->model(), config));
  Arena arena(block.data(), block.size());
  GraspGuard<3, double> guard;
  GraspObject<3, double> object;
  object.squeeze_axis = Eigen::Vector3d(1, 0, 0);
  ASSERT_EQ(grasp_guard_init(arena, plant->model(), object, config, guard), Status::ok);
  const double predicted = grasp_guard_predicted_strain(guard, closure, beta, beta);
  EXPECT_GT(strain, 0.01);
  EXPECT_NEAR(strain, predicted, 0.03 * predicted);
  // The guard's own gauge on the plant's state agrees with the plant's ground truth.
  GraspStrainMeasurement measured;
  ASSERT_EQ(grasp_guard_measure_strain(plant->model(), guard, plant->positions(), measured), Status::ok);
  EXPECT_NEAR(measured.strain, strain, 1e-9);
  EXPECT_LE(plant->true_max_strain(), plant->peak_true_strain());
}

// In MSM, stiffer clusters (lower beta) concentrate the squeeze at the jaws.
TEST(HalSimulatedGrasp, LowerBetaStrainsMoreAtTheSameClosure) {
  const double stiff = HeldSqueeze(0.1, 0.001).plant.true_max_strain();
  const double soft = HeldSqueeze(0.9, 0.001).plant.true_max_strain();
  EXPECT_GT(stiff, soft);
  EXPECT_GT(soft, 0.0);
}

TEST(HalSimulatedGrasp, ForceLawReleaseAndCatchUp) {
  SteppedClock t;
  SimulatedGrasp plant(t.clock);
  SimulatedGraspConfig c = test::small_grasp();
  c.object.stiffening = 2.0;
  c.max_catch_up_periods = 50;
  ASSERT_EQ(plant.configure(c), HalStatus::ok);
  const double e = plant.extent_m();
  EXPECT_EQ(plant.force_at(-0.001), 0.0);
  EXPECT_NEAR(plant.force_at(0.002), 2000 * 0.002 * (1 + 2.0 * 0.002 / e), 1e-12);
  // Squeeze 1 mm, then open: the contact is released and the object relaxes to rest.
  plant.command_move(e - 0.001, 0.01, 1000);
  for (int k = 0; k < 400; ++k) {
    t.step();
    plant.sync();
  }
  EXPECT_NEAR(plant.closure_m(), 0.001, 1e-12);
  EXPECT_NEAR(plant.grip_force_n(), plant.force_at(0.001), 1e-12);
  const double squeezed = plant.true_max_strain();
  EXPECT_GT(squeezed, 0.005);
  EXPECT_NEAR(plant.peak_true_strain(), squeezed, 1e-12 * squeezed);
  plant.command_open(0.05);
  for (int k = 0; k < 600; ++k) {
    t.step();
    plant.sync();
  }
  EXPECT_EQ(plant.contact_count(), 0);
  EXPECT_EQ(plant.grip_force_n(), 0.0);
  EXPECT_LT(plant.true_max_strain(), 1e-6);
  EXPECT_NEAR(plant.peak_true_strain(), squeezed, 1e-12 * squeezed);
  // A long gap is bounded: 50 periods simulated, the rest skipped and counted.
  const std::uint64_t periods = plant.counters().periods;
  t.step(500);
  plant.sync();
  EXPECT_EQ(plant.counters().periods - periods, 50u);
  EXPECT_EQ(plant.counters().skipped_periods, 450u);
  EXPECT_NEAR(plant.time_s(), t.now(), 1e-9);
  EXPECT_EQ(plant.counters().step_errors, 0u);
  plant.reset();
  EXPECT_EQ(plant.peak_true_strain(), 0.0);
  EXPECT_EQ(plant.width_m(), 0.034);
}

}  // namespace
}  // namespace pliant::hal
