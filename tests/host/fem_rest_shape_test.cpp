// estimate_rest_shape: round trips through the forward static solver (a clamped cantilever and
// a bent, tapered bar), the analytic rest length of a hanging column, the stiff limit, noise,
// the recording overload and the inputs it must refuse. Prints the quality figures of Wang et
// al.'s Table 2 (mean |dX|, mean |dx_s|) for each test shape.
#include "pliant/host/fem/estimate_rest_shape.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_recording.hpp"
#include "pliant/host/fem/fem_solver.hpp"

namespace {

using pliant::host::Recording;
using pliant::host::TetMesh;
using pliant::host::fem::BoxSplit;
using pliant::host::fem::estimate_rest_shape;
using pliant::host::fem::fem_problem_from_recording;
using pliant::host::fem::FemMaterial;
using pliant::host::fem::FemModel;
using pliant::host::fem::FemSolver;
using pliant::host::fem::FemStaticOptions;
using pliant::host::fem::make_box_tet_mesh;
using pliant::host::fem::points_on_plane;
using pliant::host::fem::RestShapeMethod;
using pliant::host::fem::RestShapeOptions;
using pliant::host::fem::RestShapeResult;

constexpr double kLength = 0.2;  // m, every test body
constexpr double kGravity = 9.81;
constexpr double kPi = 3.14159265358979323846;

Eigen::VectorXd points_of(const TetMesh& mesh) {
  return Eigen::Map<const Eigen::VectorXd>(mesh.points.data(), static_cast<Eigen::Index>(mesh.points.size()));
}

double max_node_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double worst = 0;
  for (Eigen::Index i = 0; i < a.size() / 3; ++i)
    worst = std::max(worst, (a.segment<3>(3 * i) - b.segment<3>(3 * i)).norm());
  return worst;
}

double mean_node_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double sum = 0;
  const Eigen::Index n = a.size() / 3;
  for (Eigen::Index i = 0; i < n; ++i) sum += (a.segment<3>(3 * i) - b.segment<3>(3 * i)).norm();
  return sum / static_cast<double>(n);
}

FemMaterial soft_material(double youngs_pa, double poisson = 0.3) {
  FemMaterial m;
  m.youngs_modulus_pa = youngs_pa;
  m.poisson_ratio = poisson;
  m.density_kg_m3 = 1000;
  m.gravity_m_s2 = Eigen::Vector3d(0, 0, -kGravity);
  return m;
}

// Bar 0.2 x 0.03 x 0.03 m along x, 10 x 2 x 2 cells, the cross-section centred on the x axis.
TetMesh bar_mesh() {
  return make_box_tet_mesh(Eigen::Vector3d(kLength, 0.03, 0.03), {10, 2, 2}, BoxSplit::mirrored_kuhn,
                           Eigen::Vector3d(0, -0.015, -0.015));
}

// The same bar, its axis bent through 60 degrees in the horizontal plane and its cross-section
// tapered to half size at the free end: gravity bends and twists it.
TetMesh bent_tapered_mesh() {
  TetMesh mesh = bar_mesh();
  const double radius = kLength / (kPi / 3.0);
  for (std::size_t i = 0; i < mesh.points.size(); i += 3) {
    const double s = mesh.points[i];
    const double taper = 1.0 - 0.5 * s / kLength;
    const double y = taper * mesh.points[i + 1];
    const double z = taper * mesh.points[i + 2];
    const double angle = s / radius;
    mesh.points[i] = radius * std::sin(angle) - y * std::sin(angle);
    mesh.points[i + 1] = radius * (1.0 - std::cos(angle)) + y * std::cos(angle);
    mesh.points[i + 2] = z;
  }
  return mesh;
}

// Static shape under gravity from the given rest shape, converged far below the test tolerances.
Eigen::VectorXd forward_static(const FemModel& model, const std::vector<int>& fixed) {
  FemSolver solver(model, fixed, {});
  FemStaticOptions options;
  options.displacement_tolerance_m = 1e-13;
  options.max_iterations = 500;
  const auto result = solver.solve_static(Eigen::VectorXd(), Eigen::VectorXd(), options);
  EXPECT_TRUE(result.converged);
  return result.position_m;
}

void print_quality(const char* shape, const RestShapeResult& r, const Eigen::VectorXd& true_rest,
                   const Eigen::VectorXd& observed) {
  const double d_rest = mean_node_distance(r.rest_position_m, true_rest);
  std::printf(
      "[rest shape] %s: max sag %.4g m (%.2f %% of length), %d iterations (%d load steps), residual %.3g N "
      "(initial %.3g N)\n"
      "             mean |dX| %.3g m, max |dX| %.3g m; forward check mean |dx_s| %.3g m, max %.3g m; "
      "normalized by length: %.3g, %.3g\n",
      shape, r.max_sag_m, 100.0 * r.max_sag_m / kLength, r.iterations, r.load_steps, r.residual_n, r.initial_residual_n,
      d_rest, max_node_distance(r.rest_position_m, true_rest), r.forward_check_mean_error_m, r.forward_check_error_m,
      d_rest / kLength, r.forward_check_mean_error_m / kLength);
  (void)observed;
}

struct RoundTrip {
  Eigen::VectorXd rest;
  Eigen::VectorXd observed;
  std::vector<int> fixed;
};

RoundTrip round_trip_case(const TetMesh& mesh, const FemModel& model) {
  RoundTrip c;
  c.rest = points_of(mesh);
  c.fixed = points_on_plane(bar_mesh(), 0, 0.0, 1e-9);  // same numbering in both meshes
  c.observed = forward_static(model, c.fixed);
  return c;
}

TEST(FemRestShape, RoundTripClampedCantilever) {
  const TetMesh mesh = bar_mesh();
  const FemModel model(mesh, soft_material(1e6));
  const RoundTrip c = round_trip_case(mesh, model);
  const RestShapeResult r = estimate_rest_shape(model, c.fixed, c.observed);
  print_quality("cantilever 0.2 m, E 1 MPa", r, c.rest, c.observed);
  ASSERT_TRUE(r.converged) << r.message;
  // The setup sags visibly: 5-10 % of the length at the tip.
  EXPECT_GT(r.max_sag_m, 0.05 * kLength);
  EXPECT_LT(r.max_sag_m, 0.10 * kLength);
  EXPECT_LT(max_node_distance(r.rest_position_m, c.rest), 1e-6 * kLength);
  EXPECT_TRUE(r.forward_check_converged);
  EXPECT_LT(r.forward_check_error_m, 1e-6 * kLength);
  EXPECT_LE(r.iterations, 8);
  EXPECT_EQ(r.load_steps, 1);
  EXPECT_NEAR(r.total_mass_kg, 1000 * kLength * 0.03 * 0.03, 1e-12);
}

TEST(FemRestShape, RoundTripBentTaperedBar) {
  const TetMesh mesh = bent_tapered_mesh();
  const FemModel model(mesh, soft_material(5e5));
  const RoundTrip c = round_trip_case(mesh, model);
  const RestShapeResult r = estimate_rest_shape(model, c.fixed, c.observed);
  print_quality("bent (60 deg) tapered bar, E 500 kPa", r, c.rest, c.observed);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_GT(r.max_sag_m, 0.05 * kLength);
  EXPECT_LT(r.max_sag_m, 0.15 * kLength);
  EXPECT_LT(max_node_distance(r.rest_position_m, c.rest), 1e-6 * kLength);
  EXPECT_LT(r.forward_check_error_m, 1e-6 * kLength);
  EXPECT_LE(r.iterations, 10);
}

TEST(FemRestShape, InverseSagIterationAgreesWithNewton) {
  const TetMesh mesh = bent_tapered_mesh();
  const FemModel model(mesh, soft_material(5e5));
  const RoundTrip c = round_trip_case(mesh, model);
  RestShapeOptions options;
  options.method = RestShapeMethod::fixed_point;
  options.max_iterations = 100;
  const RestShapeResult r = estimate_rest_shape(model, c.fixed, c.observed, options);
  print_quality("bent tapered bar, inverse-sag iteration", r, c.rest, c.observed);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_EQ(r.load_steps, 0);
  EXPECT_LT(max_node_distance(r.rest_position_m, c.rest), 1e-6 * kLength);
}

// A column of length L_obs hangs from its top face, gravity along its axis, Poisson ratio 0: a
// uniaxial bar under its own weight. With rest length L and c = rho g / (2 E) the elongation is
// c L^2, so L_obs = L + c L^2 exactly for this linear strain measure, and L = L_obs - c L_obs^2
// to first order. The observed column here is a uniform box (not produced by our forward solve).
double estimated_column_rest_length(double youngs_pa, double* c_out) {
  const double width = 0.02;
  const TetMesh mesh = make_box_tet_mesh(Eigen::Vector3d(width, width, kLength), {2, 2, 10}, BoxSplit::mirrored_kuhn,
                                         Eigen::Vector3d(-width / 2, -width / 2, -kLength));
  const FemModel model(mesh, soft_material(youngs_pa, 0.0));
  const std::vector<int> top = points_on_plane(mesh, 2, 0.0, 1e-9);
  const std::vector<int> bottom = points_on_plane(mesh, 2, -kLength, 1e-9);
  const RestShapeResult r = estimate_rest_shape(model, top, points_of(mesh));
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_LT(r.forward_check_error_m, 1e-6 * kLength);
  double bottom_z = 0;
  for (int node : bottom) bottom_z += r.rest_position_m[3 * node + 2];
  *c_out = 1000 * kGravity / (2 * youngs_pa);
  double lo = 1;
  double hi = -1;
  for (int node : bottom) {
    lo = std::min(lo, r.rest_position_m[3 * node + 2]);
    hi = std::max(hi, r.rest_position_m[3 * node + 2]);
  }
  std::printf("[rest shape] hanging column E %.4g Pa: %d iterations, bottom face rest z spread %.3g m\n", youngs_pa,
              r.iterations, hi - lo);
  return -bottom_z / static_cast<double>(bottom.size());
}

TEST(FemRestShape, HangingColumnMatchesAnalyticRestLength) {
  // 5 % elongation: compare with the exact relation and with the first-order formula.
  double c = 0;
  const double rest_length = estimated_column_rest_length(19620, &c);
  const double exact = (std::sqrt(1 + 4 * c * kLength) - 1) / (2 * c);
  const double first_order = kLength - c * kLength * kLength;
  std::printf("[rest shape] hanging column 5 %%: estimated %.7f m, exact %.7f m, first order %.7f m\n", rest_length,
              exact, first_order);
  EXPECT_NEAR(rest_length, exact, 1e-3 * (kLength - exact));
  // The first-order formula misses 2 c^2 L^3 (about 10 % of the elongation here).
  EXPECT_NEAR(rest_length - first_order, 2 * c * c * kLength * kLength * kLength,
              0.2 * 2 * c * c * std::pow(kLength, 3));

  // 0.5 % elongation: the first-order formula is good to about 1 % of the elongation.
  const double small = estimated_column_rest_length(196200, &c);
  const double small_first_order = kLength - c * kLength * kLength;
  std::printf("[rest shape] hanging column 0.5 %%: estimated %.8f m, first order %.8f m\n", small, small_first_order);
  EXPECT_NEAR(small, small_first_order, 0.015 * c * kLength * kLength);
}

TEST(FemRestShape, StiffLimitGivesTheObservedShape) {
  const TetMesh mesh = bar_mesh();
  const std::vector<int> fixed = points_on_plane(mesh, 0, 0.0, 1e-9);
  const Eigen::VectorXd observed = points_of(mesh);  // a straight bar, observed as is
  double sag_times_e[2] = {0, 0};
  const double moduli[2] = {1e10, 1e12};
  for (int k = 0; k < 2; ++k) {
    const FemModel model(mesh, soft_material(moduli[k]));
    const RestShapeResult r = estimate_rest_shape(model, fixed, observed);
    ASSERT_TRUE(r.converged) << r.message;
    EXPECT_LT(r.max_sag_m, 0.1 * kLength * 1e6 / moduli[k]);  // 7.3 % of the length at 1 MPa
    EXPECT_LT(r.forward_check_error_m, 1e-3 * r.max_sag_m);
    sag_times_e[k] = r.max_sag_m * moduli[k];
    std::printf("[rest shape] stiff limit E %.0e Pa: max |X - x_s| %.3g m, %d iterations (%s)\n", moduli[k],
                r.max_sag_m, r.iterations, r.message.c_str());
  }
  // X -> x_s like 1/E (linear regime).
  EXPECT_NEAR(sag_times_e[1] / sag_times_e[0], 1.0, 1e-3);
}

// Sag of a third of the length (a bar far softer than the round trips above): Newton still
// converges, damped where needed, and agrees with the truth.
TEST(FemRestShape, LargeSagConverges) {
  const TetMesh mesh = bent_tapered_mesh();
  const FemModel model(mesh, soft_material(1.2e5));
  const RoundTrip c = round_trip_case(mesh, model);
  const RestShapeResult r = estimate_rest_shape(model, c.fixed, c.observed);
  print_quality("bent tapered bar, E 120 kPa (large sag)", r, c.rest, c.observed);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_GT(r.max_sag_m, 0.25 * kLength);
  EXPECT_LT(max_node_distance(r.rest_position_m, c.rest), 1e-6 * kLength);
  EXPECT_LT(r.forward_check_error_m, 1e-6 * kLength);
  EXPECT_LE(r.iterations, 15);
}

// A bar sagging more than half its length (Poisson ratio 0.45): the full-load Newton iteration
// leaves its basin, so the load is applied in steps; the answer is still exact.
TEST(FemRestShape, VeryLargeSagUsesLoadSteps) {
  const TetMesh mesh = bar_mesh();
  const FemModel model(mesh, soft_material(1e5, 0.45));
  const RoundTrip c = round_trip_case(mesh, model);
  const RestShapeResult r = estimate_rest_shape(model, c.fixed, c.observed);
  print_quality("cantilever, E 100 kPa, nu 0.45 (very large sag)", r, c.rest, c.observed);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_GT(r.max_sag_m, 0.5 * kLength);
  EXPECT_GT(r.load_steps, 1);
  EXPECT_LT(max_node_distance(r.rest_position_m, c.rest), 1e-6 * kLength);
  EXPECT_LT(r.forward_check_error_m, 1e-6 * kLength);
}

TEST(FemRestShape, NoisyObservationConvergesAndErrorScalesWithNoise) {
  const TetMesh mesh = bar_mesh();
  const FemModel model(mesh, soft_material(1e6));
  const RoundTrip c = round_trip_case(mesh, model);
  std::mt19937 generator(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd pattern(c.observed.size());
  for (Eigen::Index i = 0; i < pattern.size(); ++i) pattern[i] = normal(generator);
  double errors[2] = {0, 0};
  const double sigmas[2] = {1e-5 * kLength, 1e-4 * kLength};
  for (int k = 0; k < 2; ++k) {
    const Eigen::VectorXd noisy = c.observed + sigmas[k] * pattern;
    const RestShapeResult r = estimate_rest_shape(model, c.fixed, noisy);
    ASSERT_TRUE(r.converged) << r.message;
    EXPECT_LE(r.iterations, 10);
    EXPECT_LT(r.forward_check_error_m, 1e-6 * kLength);  // reproduces the noisy shape
    errors[k] = max_node_distance(r.rest_position_m, c.rest);
    std::printf(
        "[rest shape] noise sigma %.1e m (%.0e of length): max |dX| %.3g m, mean |dX| %.3g m, "
        "%d iterations\n",
        sigmas[k], sigmas[k] / kLength, errors[k], mean_node_distance(r.rest_position_m, c.rest), r.iterations);
  }
  // The error follows the noise (same pattern, 10x larger) and stays far below the sag.
  EXPECT_NEAR(errors[1] / errors[0], 10.0, 1.0);
  EXPECT_LT(errors[1], 30 * sigmas[1]);
}

TEST(FemRestShape, NoLoadMeansRestIsObserved) {
  const TetMesh mesh = bar_mesh();
  FemMaterial material = soft_material(1e6);
  material.gravity_m_s2.setZero();
  const FemModel model(mesh, material);
  Eigen::VectorXd observed = points_of(mesh);
  observed[observed.size() - 1] += 1e-3;  // any shape is a rest shape without load
  const RestShapeResult r = estimate_rest_shape(model, {}, observed);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_EQ(r.rest_position_m, observed);
}

// Runs `call`, expecting std::invalid_argument whose message contains `cause`.
template <typename Call>
void expect_refused(Call call, const std::string& cause) {
  try {
    call();
    ADD_FAILURE() << "no exception; expected one about: " << cause;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(cause), std::string::npos) << e.what();
  }
}

TEST(FemRestShape, RefusesBadInput) {
  const TetMesh mesh = bar_mesh();
  const FemModel model(mesh, soft_material(1e6));
  const std::vector<int> fixed = points_on_plane(mesh, 0, 0.0, 1e-9);
  const Eigen::VectorXd good = points_of(mesh);

  Eigen::VectorXd nan_shape = good;
  nan_shape[5] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(estimate_rest_shape(model, fixed, nan_shape), std::invalid_argument);
  EXPECT_THROW(estimate_rest_shape(model, fixed, good.head(good.size() - 3)), std::invalid_argument);
  // Gravity and no supports: internal forces sum to zero, no equilibrium.
  expect_refused([&] { estimate_rest_shape(model, {}, good); }, "no fixed nodes");
  // Two supports: the body could rotate about their line.
  expect_refused([&] { estimate_rest_shape(model, {fixed[0], fixed[1]}, good); }, "collinear");
  EXPECT_THROW(estimate_rest_shape(model, {-1}, good), std::invalid_argument);
  EXPECT_THROW(estimate_rest_shape(model, {fixed[0], fixed[0]}, good), std::invalid_argument);
  Eigen::VectorXd inverted = good;
  inverted.segment<3>(3 * (model.node_count() - 1)) = Eigen::Vector3d(-1, 0, 0);  // a free corner pulled through
  expect_refused([&] { estimate_rest_shape(model, fixed, inverted); }, "static shape");
  RestShapeOptions options;
  options.max_iterations = 0;
  EXPECT_THROW(estimate_rest_shape(model, fixed, good, options), std::invalid_argument);
  options = RestShapeOptions();
  options.external_force_n = Eigen::VectorXd::Zero(3);
  EXPECT_THROW(estimate_rest_shape(model, fixed, good, options), std::invalid_argument);
  options.external_force_n = Eigen::VectorXd::Zero(good.size());
  options.force_tolerance_n = -1;
  EXPECT_THROW(estimate_rest_shape(model, fixed, good, options), std::invalid_argument);

  // A second bar beside the first, not clamped: nothing holds it.
  TetMesh two = mesh;
  const int n = mesh.point_count();
  for (std::size_t i = 0; i < mesh.points.size(); i += 3) {
    two.points.insert(two.points.end(), {mesh.points[i], mesh.points[i + 1] + 0.1, mesh.points[i + 2]});
  }
  for (int node : mesh.tetrahedra) two.tetrahedra.push_back(node + n);
  const FemModel two_model(two, soft_material(1e6));
  expect_refused([&] { estimate_rest_shape(two_model, fixed, points_of(two)); }, "has no fixed nodes");
}

TEST(FemRestShape, IterationLimitIsReportedNotThrown) {
  const TetMesh mesh = bar_mesh();
  const FemModel model(mesh, soft_material(1e6));
  const RoundTrip c = round_trip_case(mesh, model);
  RestShapeOptions options;
  options.max_iterations = 1;
  const RestShapeResult r = estimate_rest_shape(model, c.fixed, c.observed, options);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_NE(r.message.find("not converged"), std::string::npos) << r.message;
  EXPECT_GT(r.residual_n, 1e-6);
}

// The cantilever as a one-frame recording: the object hanging before anything touches it.
Recording hanging_recording(const TetMesh& mesh, const Eigen::VectorXd& observed, const std::vector<int>& fixed) {
  Recording r;
  r.name = "sagging_bar";
  r.dimension = 3;
  r.length_unit = "m";
  r.particle_count = mesh.point_count();
  r.masses.assign(static_cast<std::size_t>(r.particle_count), 1.0);
  r.fixed = fixed;
  r.material = {{"youngs_modulus", 1e6}, {"density", 1000.0}, {"poisson_ratio", 0.3}};
  r.gravity = std::vector<double>{0.0, 0.0, -kGravity};
  r.mesh = mesh;
  r.rest_positions = mesh.points;
  r.frame_times_s = {0.0};
  r.positions.assign(observed.data(), observed.data() + observed.size());
  return r;
}

TEST(FemRestShape, FromRecordingFrame) {
  const TetMesh mesh = bar_mesh();
  const FemModel model(mesh, soft_material(1e6));
  const RoundTrip c = round_trip_case(mesh, model);
  const Recording recording = hanging_recording(mesh, c.observed, c.fixed);
  const RestShapeResult r = estimate_rest_shape(fem_problem_from_recording(recording), 0);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_LT(max_node_distance(r.rest_position_m, c.rest), 1e-6 * kLength);

  EXPECT_THROW(estimate_rest_shape(fem_problem_from_recording(recording), 1), std::invalid_argument);
  Recording no_density = recording;
  no_density.material.erase("density");
  EXPECT_THROW(estimate_rest_shape(fem_problem_from_recording(no_density), 0), std::invalid_argument);
  Recording no_modulus = recording;
  no_modulus.material.erase("youngs_modulus");
  EXPECT_THROW(estimate_rest_shape(fem_problem_from_recording(no_modulus), 0), std::invalid_argument);
  Recording no_gravity = recording;
  no_gravity.gravity.reset();
  EXPECT_THROW(estimate_rest_shape(fem_problem_from_recording(no_gravity), 0), std::invalid_argument);
  Recording occluded = recording;
  occluded.positions[3 * 20] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(estimate_rest_shape(fem_problem_from_recording(occluded), 0), std::invalid_argument);
  Recording driven = recording;
  driven.driven.push_back({c.fixed.back() + 1, 0.0, 1.0});
  EXPECT_THROW(estimate_rest_shape(fem_problem_from_recording(driven), 0), std::invalid_argument);
}

// A measured wrench at the frame (a weight hung on the tip) is a dead load on applied_to.
TEST(FemRestShape, FromRecordingFrameWithWrench) {
  const TetMesh mesh = bar_mesh();
  const FemModel model(mesh, soft_material(1e6));
  const std::vector<int> fixed = points_on_plane(mesh, 0, 0.0, 1e-9);
  const std::vector<int> tip = points_on_plane(mesh, 0, kLength, 1e-9);
  const Eigen::Vector3d weight(0, 0, -0.05);  // N, about a third of the bar's own weight
  Eigen::VectorXd load;
  pliant::host::fem::add_spread_force(weight, tip, model.node_count(), load);
  FemSolver solver(model, fixed, {});
  FemStaticOptions options;
  options.displacement_tolerance_m = 1e-13;
  options.max_iterations = 500;
  const Eigen::VectorXd observed = solver.solve_static(Eigen::VectorXd(), load, options).position_m;

  Recording recording = hanging_recording(mesh, observed, fixed);
  recording.wrench_applied_to = tip;
  pliant::host::WrenchSample w0;
  pliant::host::WrenchSample w1;
  w1.t_s = 1.0;
  for (int a = 0; a < 3; ++a) {
    w0.force_n[static_cast<std::size_t>(a)] = weight[a];
    w1.force_n[static_cast<std::size_t>(a)] = weight[a];
  }
  recording.wrench = {w0, w1};
  const RestShapeResult r = estimate_rest_shape(fem_problem_from_recording(recording), 0);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_LT(max_node_distance(r.rest_position_m, points_of(mesh)), 1e-6 * kLength);
  EXPECT_LT(r.forward_check_error_m, 1e-6 * kLength);
  std::printf("[rest shape] cantilever with 0.05 N on the tip: max sag %.4g m, %d iterations\n", r.max_sag_m,
              r.iterations);

  // Without the wrench the same shape needs a different (more curved-up) rest shape.
  const RestShapeResult gravity_only = estimate_rest_shape(model, fixed, observed);
  EXPECT_GT(max_node_distance(gravity_only.rest_position_m, points_of(mesh)), 1e-3 * kLength);
}

}  // namespace
