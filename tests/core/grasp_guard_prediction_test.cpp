// The grasp guard's physics: its strain gauge against known affine deformations (SVD), its
// prediction table against the analytic uniform compression, and its predicted safe closure
// against an independent squeeze of the same MSM model at the true msm_beta.
//
// The reference squeeze below shares only msm_step with the guard: its own loading path (32x
// finer closure steps, no refinement), its own relaxation (velocities zeroed after every step,
// no momentum, a 100x tighter tolerance), its own contact bookkeeping and its own strain
// (Eigen's JacobiSVD of each cluster's affine fit on a span basis from Eigen's iterative
// eigensolver).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include "grasp_guard_fixture.hpp"

namespace pliant {
namespace {

using test::GuardedObject;

// Largest |principal stretch - 1| of cluster c, by SVD of the affine fit on the cluster's span.
template <int Dim, typename Scalar>
double svd_cluster_strain(const MsmModel<Dim, Scalar>& model, int c, const Eigen::Matrix<Scalar, Dim, 1>* x) {
  using MatD = Eigen::Matrix<double, Dim, Dim>;
  MatD apq = MatD::Zero();
  Eigen::Matrix<double, Dim, 1> centroid = Eigen::Matrix<double, Dim, 1>::Zero();
  double mass = 0;
  for (int k = model.cluster_begin[c]; k < model.cluster_begin[c + 1]; ++k) {
    const int j = model.members[k];
    centroid += static_cast<double>(model.mass[j]) * x[j].template cast<double>();
    mass += static_cast<double>(model.mass[j]);
  }
  centroid /= mass;
  for (int k = model.cluster_begin[c]; k < model.cluster_begin[c + 1]; ++k) {
    const int j = model.members[k];
    apq += static_cast<double>(model.mass[j]) * (x[j].template cast<double>() - centroid) *
           model.member_rest_offset[k].template cast<double>().transpose();
  }
  const MatD aqq_inverse = model.cluster_aqq_inverse[c].template cast<double>();
  const MatD a = apq * aqq_inverse;
  Eigen::SelfAdjointEigenSolver<MatD> span(aqq_inverse);
  const double largest = span.eigenvalues().cwiseAbs().maxCoeff();
  double worst = 0;
  Eigen::Matrix<double, Dim, Eigen::Dynamic> basis(Dim, 0);
  for (int d = 0; d < Dim; ++d) {
    if (span.eigenvalues()(d) > 1e-5 * largest) {
      basis.conservativeResize(Eigen::NoChange, basis.cols() + 1);
      basis.col(basis.cols() - 1) = span.eigenvectors().col(d);
    }
  }
  const Eigen::MatrixXd restricted = a * basis;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(restricted);
  for (Eigen::Index d = 0; d < svd.singularValues().size(); ++d) {
    worst = std::max(worst, std::abs(svd.singularValues()(d) - 1.0));
  }
  return worst;
}

template <int Dim, typename Scalar>
double svd_strain(const MsmModel<Dim, Scalar>& model, const Eigen::Matrix<Scalar, Dim, 1>* x) {
  double worst = 0;
  for (int c = 0; c < model.cluster_count; ++c) worst = std::max(worst, svd_cluster_strain(model, c, x));
  return worst;
}

// The reference squeeze: jaws normal to x, each advancing closure / 2; particles within a
// quarter spacing of the extremes start in contact; at equilibrium, particles past a jaw join
// it (projected) and the relaxation repeats.
template <int Dim, typename Scalar>
struct ReferenceSqueeze {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  const MsmModel<Dim, Scalar>& model;
  std::vector<unsigned char> block;
  MsmState<Dim, Scalar> state;
  std::vector<int> side;
  std::vector<Vec> anchor;
  std::vector<double> anchor_closure;
  double low = 0, high = 0, tolerance = 0;
  long steps = 0;
  bool converged = true;

  ReferenceSqueeze(const MsmModel<Dim, Scalar>& m, double beta) : model(m) {
    block.resize(msm_state_workspace_size(model));
    Arena arena(block.data(), block.size());
    EXPECT_EQ(msm_state_init(arena, model, state), Status::ok);
    params.msm_beta = static_cast<Scalar>(beta);
    const int n = model.particle_count;
    low = std::numeric_limits<double>::infinity();
    high = -low;
    double coordinate = 0;
    for (int i = 0; i < n; ++i) {
      low = std::min(low, static_cast<double>(model.rest[i](0)));
      high = std::max(high, static_cast<double>(model.rest[i](0)));
      coordinate = std::max(coordinate, static_cast<double>(model.rest[i].cwiseAbs().maxCoeff()));
    }
    const double h = static_cast<double>(model.spacing);
    tolerance = std::max(1e-8 * h, 8.0 * static_cast<double>(std::numeric_limits<Scalar>::epsilon()) * coordinate);
    side.assign(static_cast<std::size_t>(n), 0);
    anchor.assign(model.rest, model.rest + n);
    anchor_closure.assign(static_cast<std::size_t>(n), 0.0);
    for (int i = 0; i < n; ++i) {
      const double x = static_cast<double>(model.rest[i](0));
      if (x <= low + 0.25 * h) side[static_cast<std::size_t>(i)] = -1;
      if (x >= high - 0.25 * h) side[static_cast<std::size_t>(i)] = 1;
    }
  }

  void relax(double closure) {
    const int n = model.particle_count;
    const double a = low + 0.5 * closure;
    const double b = high - 0.5 * closure;
    for (int pass = 0; pass < 1000; ++pass) {
      std::vector<int> ids;
      std::vector<Vec> targets;
      for (int i = 0; i < n; ++i) {
        const auto u = static_cast<std::size_t>(i);
        if (side[u] == 0) continue;
        Vec target = anchor[u];
        target(0) += static_cast<Scalar>(-side[u] * 0.5 * (closure - anchor_closure[u]));
        ids.push_back(i);
        targets.push_back(target);
      }
      MsmStepInput<Dim, Scalar> input;
      input.dt = Scalar(1);
      input.driven.ids = ids.data();
      input.driven.positions = targets.data();
      input.driven.count = static_cast<int>(ids.size());
      bool settled = false;
      for (int iteration = 0; iteration < 200000 && !settled; ++iteration) {
        std::vector<Vec> previous(state.position, state.position + n);
        EXPECT_EQ(msm_step(model, params, input, state), Status::ok);
        ++steps;
        double move = 0;
        for (int i = 0; i < n; ++i) {
          state.velocity[i].setZero();
          move =
              std::max(move, static_cast<double>((state.position[i] - previous[static_cast<std::size_t>(i)]).norm()));
        }
        settled = move <= tolerance;
      }
      converged = converged && settled;
      int joined = 0;
      for (int i = 0; i < n; ++i) {
        const auto u = static_cast<std::size_t>(i);
        const double x = static_cast<double>(state.position[i](0));
        if (side[u] != 0 || (x >= a && x <= b)) continue;
        side[u] = x < a ? -1 : 1;
        state.position[i](0) = static_cast<Scalar>(x < a ? a : b);
        anchor[u] = state.position[i];
        anchor_closure[u] = closure;
        ++joined;
      }
      if (joined == 0) return;
    }
  }

  /// Loads in steps of `step` until the strain exceeds `limit`; returns that closure (NaN if
  /// never within `max_closure`) and leaves `strain_at_half` the strain at about half of it.
  double first_crossing(double step, double max_closure, double limit) {
    for (int k = 1; k * step <= max_closure; ++k) {
      relax(k * step);
      strains.push_back(svd_strain(model, state.position));
      if (strains.back() > limit) return k * step;
    }
    return std::numeric_limits<double>::quiet_NaN();
  }

  MsmParams<Dim, Scalar> params;
  std::vector<double> strains;  // at step, 2 step, ...
};

template <int D, typename S>
struct Case {
  static constexpr int kDim = D;
  using Scalar = S;
};
struct CaseNames {
  template <typename C>
  static std::string GetName(int) {
    return std::to_string(C::kDim) + "d_" + (std::is_same<typename C::Scalar, float>::value ? "float" : "double");
  }
};
using Cases = ::testing::Types<Case<2, float>, Case<2, double>, Case<3, float>, Case<3, double>>;

template <typename C>
class GraspGuardPrediction : public ::testing::Test {};
TYPED_TEST_SUITE(GraspGuardPrediction, Cases, CaseNames);

// The gauge against known affine maps x = R F rest + t: every cluster's strain is the largest
// |singular value of F - 1| (here from JacobiSVD), whatever the rotation and translation.
TYPED_TEST(GraspGuardPrediction, StrainGaugeMatchesSvdOfKnownDeformations) {
  constexpr int Dim = TypeParam::kDim;
  using Scalar = typename TypeParam::Scalar;
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  using MatD = Eigen::Matrix<double, Dim, Dim>;
  GuardedObject<Dim, Scalar> object(test::lattice<Dim, Scalar>(5, 4, 3, 0.01));
  GraspGuardConfig config;
  config.prediction_beta_points = 2;
  config.prediction_closure_points = 4;
  ASSERT_EQ(object.build_guard(config), Status::ok);
  // The model's own A_qq^+ (Eigen's closed-form eigensolver in msm_model) is good to ~1e-9 in
  // double; the two gauges, evaluating the same fit, agree far better than that.
  const double tolerance = std::is_same<Scalar, float>::value ? 2e-5 : 1e-8;
  const double agreement = std::is_same<Scalar, float>::value ? 1e-6 : 1e-12;

  MatD rotation = MatD::Identity();
  if constexpr (Dim == 2) {
    rotation = Eigen::Rotation2D<double>(0.7).toRotationMatrix();
  } else {
    rotation = Eigen::AngleAxis<double>(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  }
  std::vector<MatD> maps;
  maps.push_back(MatD::Identity());
  MatD compress = MatD::Identity();
  compress(0, 0) = 0.93;
  maps.push_back(compress);
  MatD shear = MatD::Identity();
  shear(0, 1) = 0.08;
  shear(1, 1) = 1.04;
  maps.push_back(shear);
  for (const MatD& f : maps) {
    const MatD full = rotation * f;
    Eigen::JacobiSVD<MatD> svd(f);
    double expected = 0;
    for (int d = 0; d < Dim; ++d) expected = std::max(expected, std::abs(svd.singularValues()(d) - 1.0));
    std::vector<Vec> x(static_cast<std::size_t>(object.particle_count()));
    for (int i = 0; i < object.particle_count(); ++i) {
      Eigen::Matrix<double, Dim, 1> p = full * object.model.rest[i].template cast<double>();
      p(0) += 0.3;
      x[static_cast<std::size_t>(i)] = p.template cast<Scalar>();
    }
    GraspStrainMeasurement m;
    ASSERT_EQ(grasp_guard_measure_strain(object.model, object.guard, x.data(), m), Status::ok);
    EXPECT_EQ(m.clusters_measured, object.model.cluster_count);
    EXPECT_EQ(m.clusters_skipped, 0);
    EXPECT_NEAR(m.strain, expected, tolerance) << "map\n" << f;
    EXPECT_NEAR(m.strain, svd_strain(object.model, x.data()), agreement);
  }
  // An unobserved particle removes the clusters holding it, and only those.
  std::vector<Vec> x(object.model.rest, object.model.rest + object.particle_count());
  x[7](0) = std::numeric_limits<Scalar>::quiet_NaN();
  GraspStrainMeasurement m;
  ASSERT_EQ(grasp_guard_measure_strain(object.model, object.guard, x.data(), m), Status::ok);
  EXPECT_EQ(m.clusters_skipped, object.model.particle_cluster_begin[8] - object.model.particle_cluster_begin[7]);
  EXPECT_NEAR(m.strain, 0.0, tolerance);
  for (Vec& p : x) p(0) = std::numeric_limits<Scalar>::quiet_NaN();
  EXPECT_EQ(grasp_guard_measure_strain(object.model, object.guard, x.data(), m), Status::no_observations);
  EXPECT_TRUE(std::isnan(m.strain));
}

// A flat object (one particle deep in 3D, or a single row in 2D) has clusters that span fewer
// dimensions than space: a rigid rotation must read 0, a stretch in its span the stretch.
TYPED_TEST(GraspGuardPrediction, FlatClustersIgnoreTheDirectionsTheyDoNotSpan) {
  constexpr int Dim = TypeParam::kDim;
  using Scalar = typename TypeParam::Scalar;
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  GuardedObject<Dim, Scalar> object(Dim == 3 ? test::lattice<Dim, Scalar>(6, 4, 1, 0.01)
                                             : test::lattice<Dim, Scalar>(8, 1, 1, 0.01));
  GraspGuardConfig config;
  config.prediction_beta_points = 2;
  config.prediction_closure_points = 4;
  ASSERT_EQ(object.build_guard(config), Status::ok);
  const double tolerance = std::is_same<Scalar, float>::value ? 2e-5 : 1e-8;
  Eigen::Matrix<double, Dim, Dim> rotation;
  if constexpr (Dim == 2) {
    rotation = Eigen::Rotation2D<double>(1.1).toRotationMatrix();
  } else {
    rotation = Eigen::AngleAxis<double>(1.1, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
  }
  std::vector<Vec> rotated, stretched;
  for (int i = 0; i < object.particle_count(); ++i) {
    const Eigen::Matrix<double, Dim, 1> r = object.model.rest[i].template cast<double>();
    rotated.push_back((rotation * r).template cast<Scalar>());
    Eigen::Matrix<double, Dim, 1> s = r;
    s(0) *= 1.06;
    stretched.push_back((rotation * s).template cast<Scalar>());
  }
  GraspStrainMeasurement m;
  ASSERT_EQ(grasp_guard_measure_strain(object.model, object.guard, rotated.data(), m), Status::ok);
  EXPECT_NEAR(m.strain, 0.0, tolerance);
  ASSERT_EQ(grasp_guard_measure_strain(object.model, object.guard, stretched.data(), m), Status::ok);
  EXPECT_NEAR(m.strain, 0.06, tolerance);
}

// msm_beta = 1 makes every cluster's goal its own affine fit, so a block squeezed between
// full-face jaws settles into the uniform compression: strain = closure / extent exactly.
// The tabulated row and its crossing must reproduce that analytic answer.
TYPED_TEST(GraspGuardPrediction, UniformCompressionAtBetaOneIsAnalytic) {
  constexpr int Dim = TypeParam::kDim;
  using Scalar = typename TypeParam::Scalar;
  GuardedObject<Dim, Scalar> object(test::lattice<Dim, Scalar>(8, 5, 4, 0.005));
  GraspGuardConfig config;
  config.max_strain = 0.08;
  config.prediction_beta_points = 3;
  ASSERT_EQ(object.build_guard(config), Status::ok);
  const GraspGuard<Dim, Scalar>& guard = object.guard;
  EXPECT_EQ(guard.unconverged_relaxations, 0);
  const double extent = guard.extent_m;
  EXPECT_NEAR(extent, 0.035, 1e-6);
  const double* row = guard.strain_table + 2 * (guard.closure_points + 1);  // beta = 1
  for (int k = 1; k <= guard.closure_points; ++k) {
    const double closure = k * guard.closure_step_m;
    if (closure / extent > 2.5 * config.max_strain) break;  // past the part the table computes
    EXPECT_NEAR(row[k], closure / extent, 2e-4) << "k " << k;
  }
  const double exact = config.max_strain * extent;
  const double resolution = guard.closure_step_m / config.prediction_refine_steps;
  EXPECT_LE(guard.crossing_closure_m[2], exact + 1e-9);
  EXPECT_GE(guard.crossing_closure_m[2], exact - resolution - 1e-6);
  // Lower beta concentrates the squeeze at the jaws: never less strain than uniform.
  EXPECT_LE(guard.crossing_closure_m[0], guard.crossing_closure_m[2]);
}

// The guard's safe closure for an estimate whose interval holds the true beta is never past
// where an independent squeeze of the model at the true beta first exceeds the strain limit,
// and not uselessly short of it. Also: the predicted strain at half that closure is an upper
// bound of the reference's, and the gauge agrees with the SVD on the reference's state.
TYPED_TEST(GraspGuardPrediction, SafeClosureIsConservativeAgainstDirectSimulation) {
  constexpr int Dim = TypeParam::kDim;
  using Scalar = typename TypeParam::Scalar;
  // A disc (point contacts that spread as the jaws close) in 2D, a block in 3D.
  GuardedObject<Dim, Scalar> object(Dim == 2 ? test::ball_rest<Dim, Scalar>(5, 0.005)
                                             : test::lattice<Dim, Scalar>(6, 4, 4, 0.005));
  GraspGuardConfig config;
  config.max_strain = 0.12;
  ASSERT_EQ(object.build_guard(config), Status::ok);
  const GraspGuard<Dim, Scalar>& guard = object.guard;
  EXPECT_EQ(guard.unconverged_relaxations, 0);

  const double resolution = guard.closure_step_m / config.prediction_refine_steps;
  const double step = guard.closure_step_m / 32;
  // The table itself: each tabulated crossing within one refined step below the reference's.
  for (int j : {0, 2, 5, 8}) {
    const double beta = static_cast<double>(j) / (guard.beta_points - 1);
    ReferenceSqueeze<Dim, Scalar> reference(object.model, beta);
    const double crossing =
        reference.first_crossing(step, guard.closure_points * guard.closure_step_m, config.max_strain);
    ASSERT_TRUE(std::isfinite(crossing)) << beta;
    EXPECT_LE(guard.crossing_closure_m[j], crossing) << "beta " << beta;
    EXPECT_GE(guard.crossing_closure_m[j], crossing - resolution - step - 1e-12) << "beta " << beta;
  }
  struct Trial {
    double truth, estimate, sd;
  };
  // The last trial puts the truth at the low-beta end of a wide interval, where the strain is
  // highest: only the worst case over the interval is conservative there.
  for (const Trial& trial :
       {Trial{0.37, 0.40, 0.03}, Trial{0.83, 0.80, 0.05}, Trial{0.12, 0.10, 0.02}, Trial{0.02, 0.25, 0.12}}) {
    SCOPED_TRACE("true beta " + std::to_string(trial.truth));
    ReferenceSqueeze<Dim, Scalar> reference(object.model, trial.truth);
    const double crossing =
        reference.first_crossing(step, guard.closure_points * guard.closure_step_m, config.max_strain);
    ASSERT_TRUE(std::isfinite(crossing));
    EXPECT_TRUE(reference.converged);
    const double k = config.confidence_k;
    const double safe =
        grasp_guard_strain_safe_closure(guard, trial.estimate - k * trial.sd, trial.estimate + k * trial.sd);
    EXPECT_LE(safe, crossing) << "the predicted safe closure is past the true crossing";
    EXPECT_GE(safe, (trial.sd > 0.1 ? 0.7 : 0.85) * crossing) << "the prediction is uselessly conservative";
    // Strain at about half the crossing: the prediction bounds the reference from above.
    const std::size_t half = reference.strains.size() / 2;
    const double closure = static_cast<double>(half + 1) * step;
    const double predicted =
        grasp_guard_predicted_strain(guard, closure, trial.estimate - k * trial.sd, trial.estimate + k * trial.sd);
    EXPECT_GE(predicted, reference.strains[half] * (1 - 1e-3));
    EXPECT_LE(predicted, reference.strains[half] * 1.35);
    // The gauge on the reference's last state against the SVD.
    GraspStrainMeasurement m;
    ASSERT_EQ(grasp_guard_measure_strain(object.model, guard, reference.state.position, m), Status::ok);
    const double gauge_tolerance = std::is_same<Scalar, float>::value ? 1e-4 : 1e-9;
    EXPECT_NEAR(m.strain, reference.strains.back(), gauge_tolerance);
  }
}

// The interval matters: widening it toward low beta (which concentrates strain) never lengthens
// the safe closure, and no estimate at all uses every tabulated beta.
TYPED_TEST(GraspGuardPrediction, WiderIntervalsAreNeverLessConservative) {
  constexpr int Dim = TypeParam::kDim;
  using Scalar = typename TypeParam::Scalar;
  GuardedObject<Dim, Scalar> object(test::ball_rest<Dim, Scalar>(Dim == 2 ? 5 : 3, 0.005));
  GraspGuardConfig config;
  config.prediction_beta_points = 6;
  config.prediction_closure_points = 16;
  ASSERT_EQ(object.build_guard(config), Status::ok);
  const auto& guard = object.guard;
  double smallest = std::numeric_limits<double>::infinity();
  for (int j = 0; j < guard.beta_points; ++j) smallest = std::min(smallest, guard.crossing_closure_m[j]);
  EXPECT_DOUBLE_EQ(grasp_guard_strain_safe_closure(guard, 0.0, 1.0), smallest);
  double previous = std::numeric_limits<double>::infinity();
  for (double half_width : {0.0, 0.05, 0.1, 0.2, 0.4, 0.6}) {
    const double safe = grasp_guard_strain_safe_closure(guard, 0.6 - half_width, 0.6 + half_width);
    EXPECT_LE(safe, previous + 1e-15) << half_width;
    previous = safe;
    EXPECT_GE(grasp_guard_predicted_strain(guard, 0.001, 0.6 - half_width, 0.6 + half_width),
              grasp_guard_predicted_strain(guard, 0.001, 0.6, 0.6) - 1e-15);
  }
}

}  // namespace
}  // namespace pliant
