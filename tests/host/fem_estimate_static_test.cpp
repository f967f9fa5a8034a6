// Quasi-static FEM estimators (estimate_static.hpp) on the simulated STEPE foam indentation
// (stepe_scenario.hpp).
//
// Built twice (tests/host/CMakeLists.txt): with PLIANT_ESTIMATE_STATIC_ACCEPTANCE=0 the quick
// tests on a small block (exactness on the estimators' own model, contracts, the scenario's
// recording); with =1 the slow STEPE analogues on the 990-node block, labelled "acceptance":
//   Table II:  Young's modulus from the force and tracked surface, starts 0.1x / 1x / 10x of
//              454 kPa, within 5 %; with gross tracking outliers too.
//   Table III: remote force from the tracked surface alone at 2 and 4 cm depth, horizontal and
//              tilted 25 deg, within 10 % of the measured force.
// Data are generated on a mesh 2x finer in x and y (3654 nodes) with noise, so the estimators never
// see their own model's output.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <ostream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pliant/host/fem/estimate_static.hpp"
#include "pliant/host/fem/stepe_scenario.hpp"
#include "pliant/host/recording.hpp"

#ifndef PLIANT_ESTIMATE_STATIC_ACCEPTANCE
#define PLIANT_ESTIMATE_STATIC_ACCEPTANCE 0
#endif

namespace {

using namespace pliant::host::fem;
using pliant::host::Recording;

constexpr double kFoamPa = 454e3;

double relative_error(double value, double truth) { return std::abs(value - truth) / std::abs(truth); }

#if !PLIANT_ESTIMATE_STATIC_ACCEPTANCE

// 7 x 5 x 4 = 140 nodes; generated on the estimation mesh itself, without noise, unless a test
// says otherwise: the estimators must then recover their own model exactly.
StepeScenarioOptions small_block() {
  StepeScenarioOptions o;
  o.name = "small_block";
  o.cells = {6, 4, 3};
  o.generation_refinement = {1, 1, 1};
  o.probe_cells = 1;
  o.peak_force_n = 300;
  o.depth_m = 0.01;
  o.ramp_frames = 2;
  o.position_noise_m = 0;
  o.force_noise_n = 0;
  return o;
}

TEST(StepeScenario, RecordingRoundTripsWithTruthBeside) {
  StepeScenarioOptions o = small_block();
  o.position_noise_m = 0.5e-3;
  o.outlier_count = 2;
  const StepeScenario s = make_stepe_scenario(o);
  const Recording& r = s.recording;
  EXPECT_EQ(r.particle_count, 7 * 5 * 4);
  EXPECT_EQ(r.fixed.size(), 35u);             // the bottom face
  EXPECT_EQ(r.wrench_applied_to.size(), 9u);  // 3 x 3 footprint
  EXPECT_EQ(r.frame_count(), 3);
  EXPECT_TRUE(r.driven.empty());
  EXPECT_EQ(r.material.count("youngs_modulus"), 0u);  // the unknown is in the truth only
  EXPECT_EQ(s.truth.at("youngs_modulus").get<double>(), kFoamPa);
  EXPECT_EQ(s.truth.at("outliers").size(), 2u);
  // The camera sees the top face minus the footprint; nothing else.
  int observed = 0;
  for (int id = 0; id < r.particle_count; ++id) observed += r.observed(1, id) ? 1 : 0;
  EXPECT_EQ(observed, 35 - 9);
  for (int id : r.wrench_applied_to) EXPECT_FALSE(r.observed(1, id));
  EXPECT_NEAR(r.wrench[2].force_n[2], -300.0, 1e-9);

  const auto dir = std::filesystem::temp_directory_path() / "pliant_stepe_scenario_roundtrip";
  std::filesystem::remove_all(dir);
  write_stepe_scenario(s, dir.string());
  const Recording back = pliant::host::read_recording(dir.string());
  EXPECT_EQ(back.particle_count, r.particle_count);
  EXPECT_EQ(back.frame_count(), r.frame_count());
  ASSERT_TRUE(r.observed(2, 112));  // a top node beside the footprint
  EXPECT_NEAR(back.position(2, 112, 2), r.position(2, 112, 2), 1e-12);
  std::ifstream truth(dir / "truth.json");
  ASSERT_TRUE(truth.good());
  EXPECT_EQ(nlohmann::json::parse(truth).at("scenario"), "stepe_foam_indentation");
  std::filesystem::remove_all(dir);
}

TEST(StepeScenario, RejectsBadOptions) {
  StepeScenarioOptions o = small_block();
  o.cells = {5, 4, 3};
  EXPECT_THROW(make_stepe_scenario(o), std::invalid_argument);
  o = small_block();
  o.declare_probe_driven = true;  // needs displacement control
  EXPECT_THROW(make_stepe_scenario(o), std::invalid_argument);
  o = small_block();
  o.probe_cells = 2;  // no margin left on a 6 x 4 grid
  EXPECT_THROW(make_stepe_scenario(o), std::invalid_argument);
}

TEST(EstimateYoungsModulusFromForce, RecoversItsOwnModelFromTenthAndTenTimes) {
  const FemRecordingProblem problem = fem_problem_from_recording(make_stepe_scenario(small_block()).recording);
  for (double start : {0.1 * kFoamPa, 10 * kFoamPa}) {
    for (bool rescale : {true, false}) {
      SCOPED_TRACE("start " + std::to_string(start) + (rescale ? " rescaled" : " plain"));
      YoungsModulusOptions o;
      o.initial_youngs_modulus_pa = start;
      o.rescale_start = rescale;
      const YoungsModulusEstimate e = estimate_youngs_modulus_from_force(problem, o);
      EXPECT_TRUE(e.converged) << e.message;
      EXPECT_LT(relative_error(e.youngs_modulus_pa, kFoamPa), 1e-4) << e.message;
      EXPECT_EQ(e.frames_used, 3);
      EXPECT_EQ(e.residual_count, 3 * 3 * 26);
      EXPECT_LT(e.position_rms_m, 1e-6);
      EXPECT_GT(e.evaluations, 0);
      EXPECT_GT(e.static_solves, 0);
    }
  }
}

TEST(EstimateYoungsModulusFromForce, EqualSharesMatchAnEqualSharesLoad) {
  StepeScenarioOptions so = small_block();
  so.equal_nodal_shares = true;
  const FemRecordingProblem problem = fem_problem_from_recording(make_stepe_scenario(so).recording);
  YoungsModulusOptions o;
  o.load_spread = LoadSpread::equal_shares;
  const YoungsModulusEstimate e = estimate_youngs_modulus_from_force(problem, o);
  EXPECT_LT(relative_error(e.youngs_modulus_pa, kFoamPa), 1e-4) << e.message;
  // The default (uniform traction) sees a different load and so a different modulus.
  const YoungsModulusEstimate traction = estimate_youngs_modulus_from_force(problem);
  EXPECT_GT(relative_error(traction.youngs_modulus_pa, kFoamPa), 1e-3) << traction.message;
}

TEST(EstimateYoungsModulusFromForce, ThreadsDoNotChangeTheResult) {
  StepeScenarioOptions so = small_block();
  so.position_noise_m = 0.3e-3;
  so.ramp_frames = 4;
  const FemRecordingProblem problem = fem_problem_from_recording(make_stepe_scenario(so).recording);
  YoungsModulusOptions o;
  o.initial_youngs_modulus_pa = 2 * kFoamPa;
  const YoungsModulusEstimate one = estimate_youngs_modulus_from_force(problem, o);
  o.threads = 2;
  const YoungsModulusEstimate two = estimate_youngs_modulus_from_force(problem, o);
  EXPECT_LT(relative_error(two.youngs_modulus_pa, one.youngs_modulus_pa), 1e-6);
  EXPECT_NEAR(one.position_noise_m, 0.3e-3, 0.06e-3);  // robust scatter of the residuals
  // The standard deviation covers the error against the truth (noise only, own model).
  EXPECT_GT(one.standard_deviation_pa, 0);
  EXPECT_LT(std::abs(one.youngs_modulus_pa - kFoamPa), 4 * one.standard_deviation_pa) << one.message;
  const std::string table = format_frame_table(one);
  EXPECT_NE(table.find("pos_rms_mm"), std::string::npos);
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 1 + 5);
}

TEST(EstimateYoungsModulusFromReaction, RecoversItsOwnModelFromADrivenPunch) {
  StepeScenarioOptions so = small_block();
  so.control = ProbeControl::displacement;
  so.declare_probe_driven = true;
  const FemRecordingProblem problem = fem_problem_from_recording(make_stepe_scenario(so).recording);
  for (bool offset : {false, true}) {
    ReactionEstimateOptions o;
    o.initial_youngs_modulus_pa = 0.1 * kFoamPa;
    o.fit_force_offset = offset;
    const YoungsModulusEstimate e = estimate_youngs_modulus_from_reaction(problem, o);
    EXPECT_TRUE(e.converged) << e.message;
    EXPECT_LT(relative_error(e.youngs_modulus_pa, kFoamPa), 1e-4) << e.message;
    EXPECT_LT(e.force_offset_n.norm(), 1e-3);
    // Frame 2: probe 1 cm into a 10 cm block under a 3 x 3-node footprint.
    ASSERT_EQ(e.frames.size(), 3u);
    EXPECT_NEAR(e.frames[2].nominal_strain, 0.1, 1e-9);
    EXPECT_NEAR(e.frames[2].simulated_force_n.z(), e.frames[2].measured_force_n.z(),
                1e-3 * std::abs(e.frames[2].measured_force_n.z()));
  }
  // The strain limit drops the 10 % frame; the rest still determines E.
  ReactionEstimateOptions o;
  o.max_nominal_strain = 0.06;
  const YoungsModulusEstimate limited = estimate_youngs_modulus_from_reaction(problem, o);
  EXPECT_EQ(limited.frames_used, 2);
  EXPECT_LT(relative_error(limited.youngs_modulus_pa, kFoamPa), 1e-4);
  // With positions weighted in (the tracked free surface agrees exactly too).
  o.position_weight = 1;
  o.position_noise_m = 1e-3;
  o.force_noise_n = 0.1;
  const YoungsModulusEstimate combined = estimate_youngs_modulus_from_reaction(problem, o);
  EXPECT_LT(relative_error(combined.youngs_modulus_pa, kFoamPa), 1e-4) << combined.message;
  EXPECT_EQ(combined.residual_count, 2 * 1 + 2 * 3 * 26);  // fz only (fx, fy read zero)
}

TEST(EstimateContactForce, BothContactModelsRecoverTheirOwnModel) {
  for (ContactModel contact : {ContactModel::spread_force, ContactModel::rigid_probe}) {
    StepeScenarioOptions so = small_block();
    so.tilt_deg = 25;
    so.control = contact == ContactModel::rigid_probe ? ProbeControl::displacement : ProbeControl::force;
    const StepeScenario s = make_stepe_scenario(so);
    ContactForceOptions o;
    o.contact = contact;
    const ContactForceEstimate e = estimate_contact_force(fem_problem_from_recording(s.recording), kFoamPa, o);
    EXPECT_TRUE(e.converged);
    ASSERT_EQ(e.frames.size(), 3u);
    EXPECT_EQ(e.compared_frames, 2);  // frame 0 measures zero force
    for (std::size_t f = 1; f < 3; ++f) {
      EXPECT_LT(e.frames[f].relative_error, 1e-3) << format_frame_table(e);
      EXPECT_GT(std::abs(e.frames[f].measured_force_n.x()), 10.0);  // the tilt shows
    }
    EXPECT_LT(std::abs(e.mean_difference_n), 1e-3 * e.mean_measured_norm_n);
    if (contact == ContactModel::rigid_probe) {
      EXPECT_NEAR(e.frames[2].probe_displacement_m.norm(), 0.01, 1e-5);
    } else {
      EXPECT_TRUE(std::isnan(e.frames[2].probe_displacement_m.x()));
    }
  }
}

TEST(EstimateStatic, RefusesUnusableProblems) {
  StepeScenarioOptions so = small_block();
  Recording r = make_stepe_scenario(so).recording;
  const FemRecordingProblem problem = fem_problem_from_recording(r);
  YoungsModulusOptions bad;
  bad.threads = 0;
  EXPECT_THROW(estimate_youngs_modulus_from_force(problem, bad), std::invalid_argument);
  bad = YoungsModulusOptions{};
  bad.initial_youngs_modulus_pa = 1;  // below the lower bound
  EXPECT_THROW(estimate_youngs_modulus_from_force(problem, bad), std::invalid_argument);
  bad = YoungsModulusOptions{};
  bad.frames.first_time_s = 100;  // no frame left
  EXPECT_THROW(estimate_youngs_modulus_from_force(problem, bad), std::invalid_argument);
  // Force control drives nothing: the reaction estimator has no load path to read.
  EXPECT_THROW(estimate_youngs_modulus_from_reaction(problem), std::invalid_argument);
  EXPECT_THROW(estimate_contact_force(problem, -1.0), std::invalid_argument);
  r.wrench.clear();
  r.wrench_applied_to.clear();
  r.files.erase("wrench");
  const FemRecordingProblem no_wrench = fem_problem_from_recording(r);
  EXPECT_THROW(estimate_youngs_modulus_from_force(no_wrench), std::invalid_argument);
  EXPECT_THROW(estimate_contact_force(no_wrench, kFoamPa), std::invalid_argument);
}

#else  // PLIANT_ESTIMATE_STATIC_ACCEPTANCE

// STEPE's foam (the scenario's defaults): 990-node estimation mesh, data from the 2x finer mesh,
// 0.5 mm tracking noise, 0.2 N force noise, a padded probe (uniform pressure on 8.6 x 8 cm)
// pushing to 1000 N (1.5 cm) in 3 frames.
StepeScenarioOptions foam_press() { return StepeScenarioOptions{}; }

TEST(StepeTableII, YoungsModulusFromTenthOneAndTenTimesWithinFivePercent) {
  const StepeScenario s = make_stepe_scenario(foam_press());
  const FemRecordingProblem problem = fem_problem_from_recording(s.recording);
  std::printf("[ table II ] %-9s %9s %8s %7s %5s %5s %7s %7s\n", "E0_kPa", "E_kPa", "sd_kPa", "err_%", "iter", "eval",
              "wall_s", "cpu_s");
  for (double factor : {0.1, 1.0, 10.0}) {
    YoungsModulusOptions o;
    o.initial_youngs_modulus_pa = factor * kFoamPa;
    const YoungsModulusEstimate e = estimate_youngs_modulus_from_force(problem, o);
    std::printf("[ table II ] %-9.1f %9.1f %8.2f %7.2f %5d %5d %7.2f %7.2f\n", factor * kFoamPa * 1e-3,
                e.youngs_modulus_pa * 1e-3, e.standard_deviation_pa * 1e-3,
                100 * (e.youngs_modulus_pa - kFoamPa) / kFoamPa, e.iterations, e.evaluations, e.wall_s, e.cpu_s);
    EXPECT_TRUE(e.converged) << e.message;
    EXPECT_LT(relative_error(e.youngs_modulus_pa, kFoamPa), 0.05) << e.message;
    EXPECT_NEAR(e.position_noise_m, 0.5e-3, 0.1e-3);
    // Its time budget (10 s CPU; the paper: 70-330 s) is judged by bench/fem_estimate_bench, not
    // here: a timed unit test fails on a loaded machine.
  }
}

TEST(StepeTableII, RobustLossRejectsGrossTrackingOutliers) {
  StepeScenarioOptions so = foam_press();
  so.outlier_count = 20;  // 20 observations (of 1260 in frames 1-3) off by 3 cm
  so.outlier_offset_m = 0.03;
  const FemRecordingProblem problem = fem_problem_from_recording(make_stepe_scenario(so).recording);
  for (RobustLoss loss : {RobustLoss::none, RobustLoss::huber, RobustLoss::cauchy}) {
    YoungsModulusOptions o;
    o.initial_youngs_modulus_pa = 0.1 * kFoamPa;
    o.fit.loss = loss;
    const YoungsModulusEstimate e = estimate_youngs_modulus_from_force(problem, o);
    const char* name = loss == RobustLoss::none ? "none" : loss == RobustLoss::huber ? "huber" : "cauchy";
    std::printf("[ outliers ] loss %-6s E %.1f kPa +- %.1f (error %+.2f %%), %d evaluations\n", name,
                e.youngs_modulus_pa * 1e-3, e.standard_deviation_pa * 1e-3,
                100 * (e.youngs_modulus_pa - kFoamPa) / kFoamPa, e.evaluations);
    if (loss != RobustLoss::none) {
      EXPECT_TRUE(e.converged) << e.message;
      EXPECT_LT(relative_error(e.youngs_modulus_pa, kFoamPa), 0.05) << name;
    }
  }
}

struct TableIIIRow {
  const char* name;
  double depth_m;
  double tilt_deg;
};

void PrintTo(const TableIIIRow& row, std::ostream* os) { *os << row.name << " " << row.depth_m * 100 << " cm"; }

class StepeTableIII : public ::testing::TestWithParam<TableIIIRow> {};

// A rigid punch (bonded, 8.6 x 8 cm) pressed to the depth in 2 frames and held 1 frame; the force
// is estimated from the tracked top surface alone over the 2 frames at full depth. The measure is
// Table III's: the mean estimate projected onto the measured direction against the mean measured
// norm. The coarse mesh's punch is stiffer or softer than the finer mesh's by up to 10 % (2 cm:
// about -9 %, 4 cm: about +5 %), which is what separates them; the whole vector is held to 15 %.
TEST_P(StepeTableIII, RemoteForceWithinTenPercentOfTheMeasuredForce) {
  const TableIIIRow row = GetParam();
  StepeScenarioOptions so;
  so.control = ProbeControl::displacement;
  so.depth_m = row.depth_m;
  so.tilt_deg = row.tilt_deg;
  so.ramp_frames = 2;
  so.hold_frames = 1;
  const StepeScenario s = make_stepe_scenario(so);
  ContactForceOptions o;
  o.contact = ContactModel::rigid_probe;
  o.frames.first_time_s = 2.0;  // frames 2 and 3, at full depth
  const ContactForceEstimate e = estimate_contact_force(fem_problem_from_recording(s.recording), kFoamPa, o);
  std::cout << format_frame_table(e);
  std::printf(
      "[ table III] %-10s depth %.0f cm  f_GT %7.1f N  f_est %7.1f N  projected %7.1f N  delta_f %+6.1f N "
      "(%+.1f %%)  wall %.1f s  cpu %.1f s\n",
      row.name, row.depth_m * 100, e.mean_measured_norm_n, e.mean_estimated_norm_n, e.mean_projected_n,
      e.mean_difference_n, 100 * e.mean_difference_n / e.mean_measured_norm_n, e.wall_s, e.cpu_s);
  EXPECT_TRUE(e.converged);
  EXPECT_EQ(e.compared_frames, 2);
  EXPECT_LT(std::abs(e.mean_difference_n), 0.10 * e.mean_measured_norm_n);
  EXPECT_LT(e.mean_relative_error, 0.15);
}

INSTANTIATE_TEST_SUITE_P(Foam, StepeTableIII,
                         ::testing::Values(TableIIIRow{"horizontal", 0.02, 0}, TableIIIRow{"horizontal", 0.04, 0},
                                           TableIIIRow{"tilted", 0.02, 25}, TableIIIRow{"tilted", 0.04, 25}),
                         [](const ::testing::TestParamInfo<TableIIIRow>& row_info) {
                           return std::string(row_info.param.name) + "_" +
                                  std::to_string(static_cast<int>(std::lround(row_info.param.depth_m * 100))) + "cm";
                         });

// STEPE's own contact model (a force spread over the footprint) on the padded probe (uniform
// pressure) pushing the surface about 1.5 cm down.
TEST(StepeTableIIISpreadForce, PaddedProbeWithinTenPercent) {
  StepeScenarioOptions so;
  so.ramp_frames = 2;
  so.hold_frames = 1;
  const StepeScenario s = make_stepe_scenario(so);
  ContactForceOptions o;
  o.frames.first_time_s = 2.0;
  const ContactForceEstimate e = estimate_contact_force(fem_problem_from_recording(s.recording), kFoamPa, o);
  std::cout << format_frame_table(e);
  std::printf("[ table III] padded probe 1000 N (travel %.1f cm): f_GT %.1f N, f_est %.1f N, delta_f %+.1f N\n",
              100 * s.truth.at("frames").back().at("probe_travel_m").get<double>(), e.mean_measured_norm_n,
              e.mean_estimated_norm_n, e.mean_difference_n);
  EXPECT_TRUE(e.converged);
  EXPECT_LT(std::abs(e.mean_difference_n), 0.10 * e.mean_measured_norm_n);
  EXPECT_LT(e.mean_relative_error, 0.10);
}

#endif  // PLIANT_ESTIMATE_STATIC_ACCEPTANCE

}  // namespace
