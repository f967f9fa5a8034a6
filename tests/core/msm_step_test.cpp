// MSM step physics: invariances the method guarantees, a symmetry, the paper's Fig. 3 as a
// property, float/double agreement, plasticity and the handling of bad input.
#include "pliant/core/msm.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "msm_fixture.hpp"

namespace {

using pliant::Status;

template <int D, typename S>
struct Kind {
  static constexpr int kDim = D;
  using Scalar = S;
};

template <typename K>
class MsmStep : public ::testing::Test {
 protected:
  static constexpr int FDim = K::kDim;
  using Scalar = typename K::Scalar;
  using FVec = Eigen::Matrix<Scalar, FDim, 1>;
  using FMat = Eigen::Matrix<Scalar, FDim, FDim>;
  static double tolerance() { return std::is_same<Scalar, float>::value ? 2e-4 : 1e-9; }

  static pliant::test::ConfigBuilder<FDim, Scalar> block(double h = 1.0) {
    pliant::test::ConfigBuilder<FDim, Scalar> b;
    b.rest = pliant::test::lattice<FDim, Scalar>(5, 4, 3, h);
    return b;
  }
  static FMat rotation() {
    FMat r;
    if constexpr (FDim == 2) {
      r << std::cos(Scalar(0.7)), -std::sin(Scalar(0.7)), std::sin(Scalar(0.7)), std::cos(Scalar(0.7));
    } else {
      r = Eigen::AngleAxis<Scalar>(Scalar(0.7), FVec(1, 2, 2).normalized()).toRotationMatrix();
    }
    return r;
  }
  // Steps with no driven particles and no forces.
  static void free_step(pliant::test::MsmFixture<FDim, Scalar>& f, const pliant::MsmParams<FDim, Scalar>& p) {
    pliant::MsmStepInput<FDim, Scalar> in;
    in.dt = Scalar(0.01);
    ASSERT_EQ(pliant::msm_step(f.model, p, in, f.state), Status::ok);
  }
};

using Kinds = ::testing::Types<Kind<2, float>, Kind<2, double>, Kind<3, float>, Kind<3, double>>;
TYPED_TEST_SUITE(MsmStep, Kinds);

TYPED_TEST(MsmStep, RestIsAnEquilibrium) {
  using T = TestFixture;
  auto b = T::block();
  pliant::test::MsmFixture<T::FDim, typename T::Scalar> f(b.config());
  ASSERT_EQ(f.status, Status::ok);
  pliant::MsmParams<T::FDim, typename T::Scalar> p;
  p.msm_beta = typename T::Scalar(0.5);
  for (int k = 0; k < 20; ++k) T::free_step(f, p);
  for (int i = 0; i < f.model.particle_count; ++i) {
    EXPECT_NEAR((f.state.position[i] - f.model.rest[i]).norm(), 0.0, T::tolerance());
  }
}

TYPED_TEST(MsmStep, RigidMotionIsPreservedWithBetaZero) {
  using T = TestFixture;
  using Vec = typename T::FVec;
  auto b = T::block();
  pliant::test::MsmFixture<T::FDim, typename T::Scalar> f(b.config());
  ASSERT_EQ(f.status, Status::ok);
  const auto r = T::rotation();
  const Vec shift = Vec::Constant(typename T::Scalar(3));
  for (int i = 0; i < f.model.particle_count; ++i) f.state.position[i] = r * f.model.rest[i] + shift;
  pliant::MsmParams<T::FDim, typename T::Scalar> p;
  p.msm_beta = 0;
  for (int k = 0; k < 5; ++k) T::free_step(f, p);
  for (int i = 0; i < f.model.particle_count; ++i) {
    EXPECT_NEAR((f.state.position[i] - (r * f.model.rest[i] + shift)).norm(), 0.0, 10 * T::tolerance());
  }
}

TYPED_TEST(MsmStep, AffineMotionIsReproducedWithBetaOne) {
  using T = TestFixture;
  using Mat = typename T::FMat;
  using Vec = typename T::FVec;
  auto b = T::block();
  pliant::test::MsmFixture<T::FDim, typename T::Scalar> f(b.config());
  ASSERT_EQ(f.status, Status::ok);
  Mat shear = Mat::Identity();
  shear(0, 1) = typename T::Scalar(0.3);
  shear(1, 1) = typename T::Scalar(0.8);
  const Mat affine = T::rotation() * shear;
  const Vec shift = Vec::Constant(typename T::Scalar(-1));
  for (int i = 0; i < f.model.particle_count; ++i) f.state.position[i] = affine * f.model.rest[i] + shift;
  pliant::MsmParams<T::FDim, typename T::Scalar> p;
  p.msm_beta = 1;
  for (int k = 0; k < 5; ++k) T::free_step(f, p);
  for (int i = 0; i < f.model.particle_count; ++i) {
    EXPECT_NEAR((f.state.position[i] - (affine * f.model.rest[i] + shift)).norm(), 0.0, 10 * T::tolerance());
  }
}

// A symmetric press (odd width, the tool on the middle column) gives a mirror-symmetric shape.
TYPED_TEST(MsmStep, SymmetricLoadGivesSymmetricAnswer) {
  using T = TestFixture;
  using Vec = typename T::FVec;
  constexpr int Dim = T::FDim;
  const int nx = 7, ny = 4, nz = Dim == 3 ? 3 : 1;
  pliant::test::ConfigBuilder<Dim, typename T::Scalar> b;
  b.rest = pliant::test::lattice<Dim, typename T::Scalar>(nx, ny, nz, 1.0);
  const int n = static_cast<int>(b.rest.size()) / Dim;
  b.fixed.assign(static_cast<std::size_t>(n), 0);
  auto id = [&](int x, int y, int z) { return (z * ny + y) * nx + x; };
  for (int z = 0; z < nz; ++z) {
    for (int x = 0; x < nx; ++x) b.fixed[static_cast<std::size_t>(id(x, 0, z))] = 1;
  }
  const int tool = id(nx / 2, ny - 1, nz / 2);
  b.drivable = {tool};
  pliant::test::MsmFixture<Dim, typename T::Scalar> f(b.config());
  ASSERT_EQ(f.status, Status::ok);
  pliant::MsmParams<Dim, typename T::Scalar> p;
  p.msm_beta = typename T::Scalar(0.6);
  Vec target = f.model.rest[tool];
  pliant::MsmStepInput<Dim, typename T::Scalar> in;
  in.dt = typename T::Scalar(1.0 / 30);
  in.driven = {&tool, &target, 1};
  for (int k = 1; k <= 60; ++k) {
    target(1) = f.model.rest[tool](1) - typename T::Scalar(0.6 * std::min(1.0, k / 30.0));
    ASSERT_EQ(pliant::msm_step(f.model, p, in, f.state), Status::ok);
  }
  const double centre = (nx - 1) / 2.0;
  double moved = 0;
  for (int z = 0; z < nz; ++z) {
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < nx; ++x) {
        const Vec a = f.state.position[id(x, y, z)];
        const Vec m = f.state.position[id(nx - 1 - x, y, z)];
        EXPECT_NEAR(static_cast<double>(a(0)) - centre, centre - static_cast<double>(m(0)), 50 * T::tolerance());
        EXPECT_NEAR(a(1), m(1), 50 * T::tolerance());
        moved = std::max(moved, static_cast<double>((a - f.model.rest[id(x, y, z)]).norm()));
      }
    }
  }
  EXPECT_GT(moved, 0.3);  // the press did deform the object
}

// Fig. 3: under the same downward force on the centre region, a larger beta deforms more.
TYPED_TEST(MsmStep, LargerBetaDeformsMore) {
  using T = TestFixture;
  using Vec = typename T::FVec;
  constexpr int Dim = T::FDim;
  const int nx = 9, ny = 4, nz = Dim == 3 ? 3 : 1;
  pliant::test::ConfigBuilder<Dim, typename T::Scalar> b;
  b.rest = pliant::test::lattice<Dim, typename T::Scalar>(nx, ny, nz, 1.0);
  const int n = static_cast<int>(b.rest.size()) / Dim;
  b.fixed.assign(static_cast<std::size_t>(n), 0);
  std::vector<Vec> force(static_cast<std::size_t>(n), Vec::Zero());
  for (int z = 0; z < nz; ++z) {
    for (int x = 0; x < nx; ++x) {
      b.fixed[static_cast<std::size_t>((z * ny) * nx + x)] = 1;
      if (x >= 3 && x <= 5) force[static_cast<std::size_t>((z * ny + ny - 1) * nx + x)](1) = typename T::Scalar(-20);
    }
  }
  double previous = -1;
  for (double beta : {0.1, 0.3, 0.5, 0.7, 0.9}) {
    pliant::test::MsmFixture<Dim, typename T::Scalar> f(b.config());
    ASSERT_EQ(f.status, Status::ok);
    pliant::MsmParams<Dim, typename T::Scalar> p;
    p.msm_beta = static_cast<typename T::Scalar>(beta);
    p.velocity_damping = 20;
    pliant::MsmStepInput<Dim, typename T::Scalar> in;
    in.dt = typename T::Scalar(0.01);
    in.external_force = force.data();
    for (int k = 0; k < 600; ++k) ASSERT_NE(pliant::msm_step(f.model, p, in, f.state), Status::invalid_argument);
    double sag = 0;
    for (int i = 0; i < n; ++i) sag += static_cast<double>(f.model.rest[i](1) - f.state.position[i](1));
    EXPECT_GT(sag, previous) << "beta " << beta;
    previous = sag;
  }
}

TYPED_TEST(MsmStep, NonFiniteTargetIsDroppedAndCounted) {
  using T = TestFixture;
  using Vec = typename T::FVec;
  auto b = T::block();
  b.drivable = {7};
  pliant::test::MsmFixture<T::FDim, typename T::Scalar> f(b.config());
  ASSERT_EQ(f.status, Status::ok);
  pliant::MsmParams<T::FDim, typename T::Scalar> p;
  Vec target = Vec::Constant(std::numeric_limits<typename T::Scalar>::quiet_NaN());
  const int id = 7;
  pliant::MsmStepInput<T::FDim, typename T::Scalar> in;
  in.dt = typename T::Scalar(0.01);
  in.driven = {&id, &target, 1};
  const Vec before = f.state.position[7];
  EXPECT_EQ(pliant::msm_step(f.model, p, in, f.state), Status::non_finite_input);
  EXPECT_EQ(f.state.dropped_targets, 1u);
  for (int i = 0; i < f.model.particle_count; ++i) EXPECT_TRUE(f.state.position[i].allFinite());
  EXPECT_EQ(f.state.position[7], before);  // fail safe: the contact holds where it was

  const int not_drivable = 3;
  target = f.model.rest[3];
  in.driven = {&not_drivable, &target, 1};
  EXPECT_EQ(pliant::msm_step(f.model, p, in, f.state), Status::non_finite_input);
  EXPECT_EQ(f.state.dropped_targets, 2u);
}

TYPED_TEST(MsmStep, BadStepInputIsRejectedAndStateUnchanged) {
  using T = TestFixture;
  using Vec = typename T::FVec;
  auto b = T::block();
  pliant::test::MsmFixture<T::FDim, typename T::Scalar> f(b.config());
  ASSERT_EQ(f.status, Status::ok);
  pliant::MsmParams<T::FDim, typename T::Scalar> p;
  pliant::MsmStepInput<T::FDim, typename T::Scalar> in;
  for (auto dt :
       {typename T::Scalar(0), typename T::Scalar(-1), std::numeric_limits<typename T::Scalar>::quiet_NaN()}) {
    in.dt = dt;
    EXPECT_EQ(pliant::msm_step(f.model, p, in, f.state), Status::invalid_argument);
  }
  in.dt = typename T::Scalar(0.01);
  std::vector<Vec> force(static_cast<std::size_t>(f.model.particle_count), Vec::Zero());
  force[2](0) = std::numeric_limits<typename T::Scalar>::infinity();
  in.external_force = force.data();
  EXPECT_EQ(pliant::msm_step(f.model, p, in, f.state), Status::non_finite_input);
  p.msm_beta = typename T::Scalar(1.5);
  in.external_force = nullptr;
  EXPECT_EQ(pliant::msm_step(f.model, p, in, f.state), Status::invalid_argument);
  EXPECT_EQ(f.state.rejected_steps, 5u);
  EXPECT_EQ(f.state.steps, 0u);
  for (int i = 0; i < f.model.particle_count; ++i) EXPECT_EQ(f.state.position[i], f.model.rest[i]);
}

TYPED_TEST(MsmStep, PlasticityLeavesAPermanentSetAfterRelease) {
  using T = TestFixture;
  using Vec = typename T::FVec;
  constexpr int Dim = T::FDim;
  auto b = T::block();
  const int n = static_cast<int>(b.rest.size()) / Dim;
  b.fixed.assign(static_cast<std::size_t>(n), 0);
  for (int i = 0; i < n; ++i) {
    if (b.rest[static_cast<std::size_t>(i * Dim + 1)] == 0) b.fixed[static_cast<std::size_t>(i)] = 1;
  }
  const int tool = n - 3;
  b.drivable = {tool};
  auto run = [&](bool plastic) {
    pliant::test::MsmFixture<Dim, typename T::Scalar> f(b.config());
    EXPECT_EQ(f.status, Status::ok);
    pliant::MsmParams<Dim, typename T::Scalar> p;
    p.msm_beta = typename T::Scalar(0.5);
    p.velocity_damping = 5;
    if (plastic) {
      p.plastic_yield = typename T::Scalar(0.02);
      p.plastic_creep = typename T::Scalar(5);
      p.plastic_max = typename T::Scalar(0.5);
    }
    Vec target = f.model.rest[tool];
    pliant::MsmStepInput<Dim, typename T::Scalar> in;
    in.dt = typename T::Scalar(1.0 / 30);
    for (int k = 1; k <= 240; ++k) {
      target(1) = f.model.rest[tool](1) - typename T::Scalar(0.8 * std::min(1.0, k / 30.0));
      in.driven = {&tool, &target, k <= 90 ? 1 : 0};
      EXPECT_NE(pliant::msm_step(f.model, p, in, f.state), Status::invalid_argument);
    }
    return static_cast<double>(f.model.rest[tool](1) - f.state.position[tool](1));
  };
  const double elastic_set = run(false);
  const double plastic_set = run(true);
  EXPECT_LT(std::abs(elastic_set), 0.02);  // elastic: back to rest
  EXPECT_GT(plastic_set, 0.05);            // plastic: stays dented
}

TEST(MsmStepPrecision, FloatAgreesWithDouble) {
  auto run = [](auto scalar_tag) {
    using S = decltype(scalar_tag);
    pliant::test::ConfigBuilder<3, S> b;
    b.rest = pliant::test::lattice<3, S>(5, 4, 3, 0.01);
    const int n = static_cast<int>(b.rest.size()) / 3;
    b.fixed.assign(static_cast<std::size_t>(n), 0);
    for (int i = 0; i < 20; ++i) b.fixed[static_cast<std::size_t>(i)] = 1;  // the z = 0 layer
    const int tool = n - 3;
    b.drivable = {tool};
    pliant::test::MsmFixture<3, S> f(b.config());
    EXPECT_EQ(f.status, Status::ok);
    pliant::MsmParams<3, S> p;
    p.msm_beta = S(0.4);
    Eigen::Matrix<S, 3, 1> target = f.model.rest[tool];
    pliant::MsmStepInput<3, S> in;
    in.dt = S(1.0 / 30);
    in.driven = {&tool, &target, 1};
    for (int k = 1; k <= 60; ++k) {
      target(2) = f.model.rest[tool](2) - S(0.004 * std::min(1.0, k / 30.0));
      EXPECT_EQ(pliant::msm_step(f.model, p, in, f.state), Status::ok);
    }
    std::vector<double> out;
    for (int i = 0; i < n; ++i) {
      for (int d = 0; d < 3; ++d) out.push_back(static_cast<double>(f.state.position[i](d)));
    }
    return out;
  };
  const auto single = run(0.0f);
  const auto dbl = run(0.0);
  ASSERT_EQ(single.size(), dbl.size());
  for (std::size_t i = 0; i < dbl.size(); ++i) EXPECT_NEAR(single[i], dbl[i], 2e-6) << i;  // 0.02 % of spacing
}

}  // namespace
