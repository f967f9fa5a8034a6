// fem_estimate_bench: accuracy and speed of the quasi-static FEM estimators (estimate_static.hpp)
// on the STEPE analogues and the real phantom compression tests. A plain program, not Google
// Benchmark: one estimate takes seconds, and its accuracy matters as much as its time.
//   a. Table II analogue: Young's modulus of the simulated foam block (454 kPa, 990-node
//      estimation mesh, data from a mesh 2x finer in x and y, 0.5 mm tracking noise, a padded
//      8.6 x 8 cm probe pushing to 1000 N) from 0.1x / 1x / 10x starts; with 2 threads; without
//      the rescaled start (plain Levenberg-Marquardt); with equal nodal shares instead of a
//      uniform traction; on data from the estimation grid itself (Kuhn split, and the estimation
//      mesh: inverse crime); with 20 gross tracking outliers under each loss. Budget (issue 17):
//      <= 5 s CPU per estimate.
//   b. Table III analogue: remote force from the tracked surface alone, rigid punch pressed 2 and
//      4 cm, horizontal and tilted 25 deg (rigid-probe contact model), and STEPE's spread-force
//      model on the 2 cm punch and on the padded probe; E = 454 kPa known.
//   c. Phantoms: Young's modulus of three silicones (examples/phantom_compression) up to 10 %
//      strain, against 3 x the lab's Neo-Hookean mu, through the origin and toe-compensated (the
//      fit `pliant refine` runs on them). Budget (issue 17): <= 2 s CPU per fit.
// Usage: fem_estimate_bench [--quick] [--sections abc]   (--quick: section a without the
// plain-LM, load-spread and other-data runs; --sections: which sections run, default all). Exit status 0 whatever the
// results (it reports, it does not judge).
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pliant/host/fem/estimate_static.hpp"
#include "pliant/host/fem/stepe_scenario.hpp"
#include "pliant/host/recording.hpp"

#ifndef PLIANT_PHANTOM_COMPRESSION_DIR
#error "PLIANT_PHANTOM_COMPRESSION_DIR must name examples/phantom_compression"
#endif
#ifndef PLIANT_BENCH_BUILD_TYPE
#define PLIANT_BENCH_BUILD_TYPE "unknown"
#endif

namespace {

using namespace pliant::host::fem;

constexpr double kFoamPa = 454e3;
constexpr double kBudgetS = 5.0;         // STEPE case, CPU s per estimate
constexpr double kPhantomBudgetS = 2.0;  // a phantom fit, CPU s

StepeScenarioOptions foam_press() { return StepeScenarioOptions{}; }  // the scenario's defaults

FemRecordingProblem simulate(const StepeScenarioOptions& options, const char* what) {
  const StepeScenario s = make_stepe_scenario(options);
  std::printf("  data: %s; generated on %d nodes in %.1f s (%d Newton iterations)\n", what, s.generation_nodes,
              s.generation_wall_s, s.generation_newton_iterations);
  return fem_problem_from_recording(s.recording);
}

void modulus_header() {
  std::printf("  %-26s %8s %9s %7s %7s %5s %5s %6s %7s %7s %7s %6s\n", "run", "E0_kPa", "E_kPa", "sd_kPa", "err_%",
              "iter", "eval", "solves", "newton", "wall_s", "cpu_s", "budget");
}

void modulus_row(const char* run, const YoungsModulusEstimate& e) {
  std::printf("  %-26s %8.1f %9.1f %7.2f %+7.2f %5d %5d %6ld %7ld %7.2f %7.2f %6s%s\n", run,
              e.initial_youngs_modulus_pa * 1e-3, e.youngs_modulus_pa * 1e-3, e.standard_deviation_pa * 1e-3,
              100 * (e.youngs_modulus_pa - kFoamPa) / kFoamPa, e.iterations, e.evaluations, e.static_solves,
              e.newton_iterations, e.wall_s, e.cpu_s, e.cpu_s <= kBudgetS ? "ok" : "MISS",
              e.converged ? "" : "  (not converged)");
}

YoungsModulusEstimate run_force(const FemRecordingProblem& problem, double start, int threads = 1, bool rescale = true,
                                RobustLoss loss = RobustLoss::huber, LoadSpread spread = LoadSpread::uniform_traction) {
  YoungsModulusOptions o;
  o.initial_youngs_modulus_pa = start;
  o.threads = threads;
  o.rescale_start = rescale;
  o.fit.loss = loss;
  o.load_spread = spread;
  return estimate_youngs_modulus_from_force(problem, o);
}

void table_ii(bool quick) {
  std::printf("== a. STEPE Table II analogue: youngs_modulus from force + tracked surface (truth 454 kPa)\n");
  const FemRecordingProblem problem = simulate(foam_press(), "1000 N padded probe, mesh 2x finer in x and y");
  modulus_header();
  char run[64];
  for (double factor : {0.1, 1.0, 10.0}) {
    std::snprintf(run, sizeof run, "start %.1fx", factor);
    modulus_row(run, run_force(problem, factor * kFoamPa));
  }
  modulus_row("start 1x, 2 threads", run_force(problem, kFoamPa, 2));
  if (!quick) {
    for (double factor : {0.1, 10.0}) {
      std::snprintf(run, sizeof run, "start %.1fx, plain LM", factor);
      try {
        modulus_row(run, run_force(problem, factor * kFoamPa, 1, false));
      } catch (const std::exception& ex) {
        std::printf("  %-26s failed: %s\n", run, ex.what());
      }
    }
    modulus_row("start 1x, equal shares",
                run_force(problem, kFoamPa, 1, true, RobustLoss::huber, LoadSpread::equal_shares));
    StepeScenarioOptions kuhn = foam_press();
    kuhn.generation_refinement = {1, 1, 1};
    kuhn.generation_split = BoxSplit::kuhn;
    const FemRecordingProblem same_grid = simulate(kuhn, "the same press on the estimation grid, Kuhn split");
    modulus_header();
    modulus_row("Kuhn-split data, start 1x", run_force(same_grid, kFoamPa));
    StepeScenarioOptions crime = kuhn;
    crime.generation_split = BoxSplit::mirrored_kuhn;
    const FemRecordingProblem own = simulate(crime, "the same press on the estimation mesh (inverse crime)");
    modulus_header();
    modulus_row("own-mesh data, start 1x", run_force(own, kFoamPa));
  }
  StepeScenarioOptions outliers = foam_press();
  outliers.outlier_count = 20;
  const FemRecordingProblem gross = simulate(outliers, "20 tracking outliers of 3 cm");
  modulus_header();
  modulus_row("outliers, no robust loss", run_force(gross, 0.1 * kFoamPa, 1, true, RobustLoss::none));
  modulus_row("outliers, huber", run_force(gross, 0.1 * kFoamPa, 1, true, RobustLoss::huber));
  modulus_row("outliers, cauchy", run_force(gross, 0.1 * kFoamPa, 1, true, RobustLoss::cauchy));
  std::printf("\n");
}

void force_row(const char* run, const char* model, double depth_cm, const ContactForceEstimate& e) {
  std::printf("  %-11s %-13s %8.1f %9.1f %9.1f %9.1f %+8.1f %+7.1f %7.3f %6d %7.2f %7.2f%s\n", run, model, depth_cm,
              e.mean_measured_norm_n, e.mean_estimated_norm_n, e.mean_projected_n, e.mean_difference_n,
              100 * e.mean_difference_n / e.mean_measured_norm_n, e.mean_relative_error, e.evaluations, e.wall_s,
              e.cpu_s, e.converged ? "" : "  (not converged)");
}

void table_iii() {
  std::printf("== b. STEPE Table III analogue: remote force from the tracked surface alone (E = 454 kPa known)\n");
  std::printf("  means over the frames at full depth; projected = estimate . measured direction\n");
  std::printf("  %-11s %-13s %8s %9s %9s %9s %8s %7s %7s %6s %7s %7s\n", "object", "contact_model", "depth_cm",
              "f_GT_N", "f_est_N", "proj_N", "delta_N", "delta_%", "rel_err", "eval", "wall_s", "cpu_s");
  struct Row {
    const char* name;
    double depth_m;
    double tilt_deg;
  };
  for (const Row& row :
       {Row{"horizontal", 0.02, 0}, Row{"horizontal", 0.04, 0}, Row{"tilted", 0.02, 25}, Row{"tilted", 0.04, 25}}) {
    StepeScenarioOptions so;
    so.control = ProbeControl::displacement;
    so.depth_m = row.depth_m;
    so.tilt_deg = row.tilt_deg;
    so.ramp_frames = 2;
    so.hold_frames = 1;
    const StepeScenario s = make_stepe_scenario(so);
    const FemRecordingProblem problem = fem_problem_from_recording(s.recording);
    for (ContactModel model : {ContactModel::rigid_probe, ContactModel::spread_force}) {
      if (model == ContactModel::spread_force && (row.tilt_deg != 0 || row.depth_m > 0.03)) continue;  // once
      ContactForceOptions o;
      o.contact = model;
      o.frames.first_time_s = 2.0;
      force_row(row.name, model == ContactModel::rigid_probe ? "rigid_probe" : "spread_force", row.depth_m * 100,
                estimate_contact_force(problem, kFoamPa, o));
    }
  }
  StepeScenarioOptions padded;
  padded.ramp_frames = 2;
  padded.hold_frames = 1;
  const StepeScenario s = make_stepe_scenario(padded);
  ContactForceOptions o;
  o.frames.first_time_s = 2.0;
  force_row("padded", "spread_force", 100 * s.truth.at("frames").back().at("probe_travel_m").get<double>(),
            estimate_contact_force(fem_problem_from_recording(s.recording), kFoamPa, o));
  std::printf("\n");
}

void phantoms() {
  std::printf("== c. Phantom compression (real data): youngs_modulus from the measured load up to 10 %% strain\n");
  const std::string dir = PLIANT_PHANTOM_COMPRESSION_DIR;
  std::ifstream in(dir + "/source/hyperelastic_parameters.json");
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json parameters = nlohmann::json::parse(text.str());
  std::printf("  %-11s %-10s %9s %7s %9s %7s %9s %5s %5s %7s %7s %6s\n", "sample", "fit", "E_kPa", "sd_kPa", "ref_kPa",
              "err_%", "offset_N", "iter", "eval", "wall_s", "cpu_s", "budget");
  const char* samples[3][2] = {{"EF10_0T", "EF10_0T_B5"}, {"EF30_0T", "EF30_0T_A5"}, {"EF50_0T", "EF50_0T_A4"}};
  for (const auto& sample : samples) {
    const double reference =
        3e3 * parameters.at("engineering").at(sample[0]).at("Neo Hookean").at("parameters").at(0).get<double>();
    const FemRecordingProblem problem = fem_problem_from_recording(pliant::host::read_recording(dir + "/" + sample[1]));
    for (bool offset : {false, true}) {
      ReactionEstimateOptions o;
      o.max_nominal_strain = 0.10;
      o.initial_youngs_modulus_pa = 1e5;
      o.fit_force_offset = offset;
      const YoungsModulusEstimate e = estimate_youngs_modulus_from_reaction(problem, o);
      std::printf("  %-11s %-10s %9.1f %7.2f %9.1f %+7.1f %9.2f %5d %5d %7.2f %7.2f %6s%s\n", sample[1],
                  offset ? "toe-comp." : "through 0", e.youngs_modulus_pa * 1e-3, e.standard_deviation_pa * 1e-3,
                  reference * 1e-3, 100 * (e.youngs_modulus_pa - reference) / reference, e.force_offset_n.z(),
                  e.iterations, e.evaluations, e.wall_s, e.cpu_s, e.cpu_s <= kPhantomBudgetS ? "ok" : "MISS",
                  e.converged ? "" : "  (not converged)");
    }
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string sections = "abc";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--quick") {
      quick = true;
    } else if (arg == "--sections" && i + 1 < argc) {
      sections = argv[++i];
    } else {
      std::fprintf(stderr, "usage: fem_estimate_bench [--quick] [--sections abc]\n");
      return arg == "--help" || arg == "-h" ? 0 : 2;
    }
  }
  std::printf("fem_estimate_bench (build type %s)\n\n", PLIANT_BENCH_BUILD_TYPE);
  const auto wall0 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  if (sections.find('a') != std::string::npos) table_ii(quick);
  if (sections.find('b') != std::string::npos) table_iii();
  if (sections.find('c') != std::string::npos) phantoms();
  std::printf("total: wall %.1f s, CPU %.1f s\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count(),
              static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC);
  return 0;
}
