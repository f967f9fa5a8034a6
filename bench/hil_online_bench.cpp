// hil_online_bench: the online msm_beta against the offline one on the HIL plant's squeezes
// (issue 20, item 4), and what the online update costs per frame.
//
// A plain program (needs the host library). For each of the twelve HIL objects, squeezed by 15 %
// of its width at 1 and at 20 mm/s (tests/hil/hil_squeeze.hpp: the plant settles between its
// 30 Hz frames), it prints the true msm_beta; `pliant estimate` with the cluster radius held at
// the setup's 1.5 spacings (the model the online estimator runs) and with its model form; the
// same with the radius chosen as well (its default); the online estimate with the rows the
// estimator had before the quasi-static row (three msm_alpha rows at one step per frame) and with
// the HIL's configuration (those rows and the quasi-static row); the difference online - offline
// (radius held) for both; and the mean CPU time of one online_deformability_update for both.
//   --no-auto   skip the radius-choosing offline fit (about half of the run time)
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "hil_squeeze.hpp"

#ifndef PLIANT_BENCH_BUILD_TYPE
#define PLIANT_BENCH_BUILD_TYPE "unknown"
#endif

namespace {

using pliant::hil::HilObject;
using pliant::hil::OnlineRun;

constexpr double kAgreement = 0.03;

// The estimator's rows before the quasi-static row: the HIL configuration without it.
pliant::OnlineDeformabilityConfig without_quasi_static_row(pliant::OnlineDeformabilityConfig config) {
  config.equilibrium_iterations = 0;
  return config;
}

struct Tally {
  int cases = 0;
  int within = 0;
  double worst = 0;
  void add(double difference) {
    ++cases;
    within += std::abs(difference) <= kAgreement ? 1 : 0;
    worst = std::max(worst, std::abs(difference));
  }
};

std::string form(double alpha, int steps) {
  char text[32];
  if (steps == 0) {
    std::snprintf(text, sizeof text, "(settled)");
  } else {
    std::snprintf(text, sizeof text, "(%.2f, %d)", alpha, steps);
  }
  return text;
}

void print_header() {
  std::printf("%-16s %4s %5s %4s | %-17s | %-22s | %-17s %7s %7s | %-17s %7s %7s\n", "object", "mm/s", "beta", "fr",
              "offline r1.5", "offline auto", "online before", "diff", "us", "online", "diff", "us");
}

void compare(const HilObject& object, double speed_m_per_s, bool with_auto, Tally& before, Tally& after) {
  pliant::hil::SqueezeOptions options;
  options.speed_m_per_s = speed_m_per_s;
  const pliant::host::Recording recording = pliant::hil::record_squeeze(object, options);
  const pliant::OnlineDeformabilityConfig config =
      pliant::hil::hil_supervisor_config(object, pliant::hil::RigOptions{}).estimator;
  const OnlineRun old_rows = pliant::hil::run_online(recording, without_quasi_static_row(config));
  const OnlineRun online = pliant::hil::run_online(recording, config);
  const pliant::host::EstimateReport held = pliant::hil::run_offline(recording, false);
  char automatic[48] = "-";
  if (with_auto) {
    const pliant::host::EstimateReport chosen = pliant::hil::run_offline(recording, true);
    std::snprintf(automatic, sizeof automatic, "%.3f+-%.3f r%.2f", chosen.result.msm_beta, chosen.msm_beta_std,
                  chosen.cluster_radius_factor);
  }
  const double offline = held.result.msm_beta;
  before.add(old_rows.estimate.msm_beta - offline);
  after.add(online.estimate.msm_beta - offline);
  std::printf("%-16s %4.0f %5.2f %4d | %5.3f %-11s | %-22s | %5.3f %-11s %+7.3f %7.0f | %5.3f %-11s %+7.3f %7.0f\n",
              object.name.c_str(), 1000 * speed_m_per_s, object.object.msm_beta, recording.frame_count(), offline,
              form(held.result.msm_alpha, held.baseline.steps_per_frame()).c_str(), automatic,
              old_rows.estimate.msm_beta, form(old_rows.estimate.msm_alpha, old_rows.estimate.steps_per_frame).c_str(),
              old_rows.estimate.msm_beta - offline, old_rows.update_cpu_us, online.estimate.msm_beta,
              form(online.estimate.msm_alpha, online.estimate.steps_per_frame).c_str(),
              online.estimate.msm_beta - offline, online.update_cpu_us);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  bool with_auto = true;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--no-auto") == 0) {
      with_auto = false;
    } else {
      std::fprintf(stderr, "usage: %s [--no-auto]\n", argv[0]);
      return 2;
    }
  }
  std::printf(
      "hil_online_bench (%s build): squeezes by 15 %% of the width, 30 Hz camera, 30 um noise; "
      "us = CPU per online update\n",
      PLIANT_BENCH_BUILD_TYPE);
  print_header();
  for (const double speed_m_per_s : {0.001, 0.02}) {
    Tally before, after;
    for (const HilObject& object : pliant::hil::hil_objects()) compare(object, speed_m_per_s, with_auto, before, after);
    std::printf(
        "%.0f mm/s: within %.2f of the offline: before %d of %d (worst %.3f), with the quasi-static row %d of "
        "%d (worst %.3f)\n",
        1000 * speed_m_per_s, kAgreement, before.within, before.cases, before.worst, after.within, after.cases,
        after.worst);
  }
  return 0;
}
