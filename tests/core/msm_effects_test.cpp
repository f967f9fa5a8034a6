// Model extensions that `diagnose` switches on: viscoelastic relaxation, strain stiffening and
// Coulomb friction at the support. Each must change the response the way its physics says and
// leave the elastic model untouched at its null value.
#include "pliant/core/msm.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "msm_fixture.hpp"

namespace {

using pliant::Status;

template <int D, typename S>
struct Kind {
  static constexpr int kDim = D;
  using Scalar = S;
};

// A 7 x 4 (x 3) block, bottom layer fixed, the top-centre particle drivable.
template <typename K>
class MsmEffects : public ::testing::Test {
 protected:
  static constexpr int Dim = K::kDim;
  using Scalar = typename K::Scalar;
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  using Params = pliant::MsmParams<Dim, Scalar>;
  using Fixture = pliant::test::MsmFixture<Dim, Scalar>;

  MsmEffects() {
    builder.rest = pliant::test::lattice<Dim, Scalar>(7, 4, 3, 1.0);
    const int n = count();
    builder.fixed.assign(static_cast<std::size_t>(n), 0);
    for (int i = 0; i < n; ++i) {
      if (builder.rest[static_cast<std::size_t>(i * Dim + 1)] == 0) builder.fixed[static_cast<std::size_t>(i)] = 1;
    }
    tool = Dim == 2 ? 3 * 7 + 3 : (1 * 4 + 3) * 7 + 3;  // top row, centre (middle layer in 3D)
    builder.drivable = {tool};
  }
  int count() const { return static_cast<int>(builder.rest.size()) / Dim; }
  static Params elastic() {
    Params p;
    p.msm_beta = Scalar(0.6);
    p.velocity_damping = Scalar(4);
    return p;
  }
  // Presses the tool `depth` down over `press_steps`, holds until `release_step`, then lets go
  // and runs to `total_steps`; calls observe(step, fixture) after every step.
  template <typename Observe>
  void press(Fixture& f, const Params& p, double depth, int press_steps, int release_step, int total_steps,
             Observe&& observe) const {
    pliant::MsmStepInput<Dim, Scalar> in;
    in.dt = Scalar(1.0 / 60);
    Vec target = f.model.rest[tool];
    for (int k = 1; k <= total_steps; ++k) {
      target(1) = f.model.rest[tool](1) - static_cast<Scalar>(depth * std::min(1.0, double(k) / press_steps));
      in.driven = {&tool, &target, k <= release_step ? 1 : 0};
      ASSERT_EQ(pliant::msm_step(f.model, p, in, f.state), Status::ok);
      observe(k, f);
    }
  }
  double drop(const Fixture& f, int id) const {
    return static_cast<double>(f.model.rest[id](1) - f.state.position[id](1));
  }

  pliant::test::ConfigBuilder<Dim, Scalar> builder;
  int tool = 0;
};

using Kinds = ::testing::Types<Kind<2, float>, Kind<2, double>, Kind<3, float>, Kind<3, double>>;
TYPED_TEST_SUITE(MsmEffects, Kinds);

TYPED_TEST(MsmEffects, RelaxationRecoversSlowlyAfterRelease) {
  using T = TestFixture;
  auto recovery = [&](double fraction) {
    typename T::Fixture f(this->builder.config());
    EXPECT_EQ(f.status, Status::ok);
    auto p = T::elastic();
    p.relaxation_fraction = static_cast<typename T::Scalar>(fraction);
    p.relaxation_time_s = typename T::Scalar(1.0);
    std::vector<double> set;  // tool particle's drop 0.5 s and 10 s after release
    this->press(f, p, 0.8, 30, 300, 300 + 600, [&](int k, const typename T::Fixture& g) {
      if (k == 300 + 30 || k == 300 + 600) set.push_back(this->drop(g, this->tool));
    });
    return set;
  };
  const std::vector<double> elastic = recovery(0.0);
  const std::vector<double> viscous = recovery(0.5);
  ASSERT_EQ(elastic.size(), 2u);
  ASSERT_EQ(viscous.size(), 2u);
  EXPECT_GT(viscous[0], elastic[0] + 0.1);  // viscoelastic: still dented half a second later...
  EXPECT_LT(std::abs(viscous[1]), 0.02);    // ...but recovered after ten relaxation times
  EXPECT_LT(std::abs(elastic[1]), 0.02);
}

TYPED_TEST(MsmEffects, StiffeningMakesTheResponseSublinear) {
  using T = TestFixture;
  using LoadVec = typename T::Vec;
  constexpr int D = T::Dim;
  // A slab under a distributed downward force on its top centre, as in the Fig. 3 test.
  const int nx = 9, ny = 4, nz = D == 3 ? 3 : 1;
  pliant::test::ConfigBuilder<D, typename T::Scalar> b;
  b.rest = pliant::test::lattice<D, typename T::Scalar>(nx, ny, nz, 1.0);
  const int n = static_cast<int>(b.rest.size()) / D;
  b.fixed.assign(static_cast<std::size_t>(n), 0);
  std::vector<int> loaded;
  for (int z = 0; z < nz; ++z) {
    for (int x = 0; x < nx; ++x) {
      b.fixed[static_cast<std::size_t>((z * ny) * nx + x)] = 1;
      if (x >= 3 && x <= 5) loaded.push_back((z * ny + ny - 1) * nx + x);
    }
  }
  auto sag = [&](double stiffening, double load) {
    typename T::Fixture f(b.config());
    EXPECT_EQ(f.status, Status::ok);
    std::vector<LoadVec> force(static_cast<std::size_t>(n), LoadVec::Zero());
    for (int id : loaded) force[static_cast<std::size_t>(id)](1) = static_cast<typename T::Scalar>(-load);
    pliant::MsmParams<D, typename T::Scalar> p;
    p.msm_beta = typename T::Scalar(0.5);
    p.velocity_damping = 20;
    p.stiffening = static_cast<typename T::Scalar>(stiffening);
    pliant::MsmStepInput<D, typename T::Scalar> in;
    in.dt = typename T::Scalar(0.01);
    in.external_force = force.data();
    for (int k = 0; k < 600; ++k) EXPECT_EQ(pliant::msm_step(f.model, p, in, f.state), Status::ok);
    double total = 0;
    for (int i = 0; i < n; ++i) total += static_cast<double>(f.model.rest[i](1) - f.state.position[i](1));
    return total;
  };
  const double plain_small = sag(0.0, 10.0);
  const double plain_large = sag(0.0, 20.0);
  // Strains here are ~1e-2, so a visible effect needs a large coefficient.
  const double stiff_small = sag(50.0, 10.0);
  const double stiff_large = sag(50.0, 20.0);
  EXPECT_EQ(plain_small, sag(0.0, 10.0));
  EXPECT_LT(stiff_small, plain_small);                                     // stiffer under the same load...
  EXPECT_LT(stiff_large / stiff_small, plain_large / plain_small - 0.03);  // ...and more so as it grows
}

TYPED_TEST(MsmEffects, SupportFrictionSlidesWhenLowAndPinsWhenHigh) {
  using T = TestFixture;
  using SupportVec = typename T::Vec;
  auto support_motion = [&](double mu, double& deepest) {
    typename T::Fixture f(this->builder.config());
    auto p = T::elastic();
    p.support_friction = static_cast<typename T::Scalar>(mu);
    p.support_normal = SupportVec::Zero();
    p.support_normal(1) = 1;
    double largest = 0;
    deepest = 0;
    this->press(f, p, 0.8, 30, 120, 120, [&](int, const typename T::Fixture& g) {
      for (int i = 0; i < this->count(); ++i) {
        if (g.model.fixed[i] == 0) continue;
        const SupportVec move = g.state.position[i] - g.model.rest[i];
        largest = std::max(largest, static_cast<double>(move.norm()));
        deepest = std::max(deepest, -static_cast<double>(move(1)));
      }
    });
    return largest;
  };
  double deepest = 0;
  const double slippery = support_motion(0.0, deepest);
  EXPECT_GT(slippery, 0.01);
  EXPECT_LT(deepest, 1e-5);  // never through the support plane
  const double sticky = support_motion(1e6, deepest);
  EXPECT_LT(sticky, 1e-4);
}

TEST(MsmEffectsParams, OutOfRangeValuesAreRejected) {
  pliant::test::ConfigBuilder<2, double> b;
  b.rest = pliant::test::lattice<2, double>(4, 3, 1, 1.0);
  pliant::test::MsmFixture<2, double> f(b.config());
  ASSERT_EQ(f.status, Status::ok);
  pliant::MsmStepInput<2, double> in;
  in.dt = 0.01;
  auto rejected = [&](const pliant::MsmParams<2, double>& p) {
    const std::uint32_t before = f.state.rejected_steps;
    return pliant::msm_step(f.model, p, in, f.state) == Status::invalid_argument &&
           f.state.rejected_steps == before + 1;
  };
  pliant::MsmParams<2, double> p;
  p.relaxation_fraction = 1.0;
  EXPECT_TRUE(rejected(p));
  p = {};
  p.relaxation_fraction = 0.3;
  p.relaxation_time_s = 0.0;
  EXPECT_TRUE(rejected(p));
  p = {};
  p.stiffening = -1.0;
  EXPECT_TRUE(rejected(p));
  p = {};
  p.support_friction = 0.5;  // finite friction needs a unit support normal
  EXPECT_TRUE(rejected(p));
  p.support_friction = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(rejected(p));
}

}  // namespace
