// Issue 20, item 4: the online msm_beta within 0.03 of the offline estimate by the end of a
// squeeze, at slow (1 mm/s) and fast (20 mm/s) closing, on the HIL's plant.
//
// Each squeeze (hil_squeeze.hpp) is recorded once; the online estimator runs through its frames
// with the HIL supervisor's configuration, then `pliant estimate` fits the same recording. The
// offline fit holds the cluster radius at the setup's 1.5 spacings, the model the online
// estimator runs: on these squeezes the radius is not determined by the frames (its automatic
// choice moves between 1.5 and 2.3 on BIC differences of 1-6, and msm_beta with it by up to 0.5,
// docs/estimation.md, "Online"), so only the same model compares. The objects are those the HIL
// test runs under sanitizers (its reduced table, msm_beta 0.75, 0.5, 0.25, 0.10, and its fault
// sweep's 0.55), soft to stiff.
//
// The plant settles between frames; the estimator's one-step rows lag it at 20 mm/s (the gel
// cube read 0.24 for the offline 0.54, the stiffening foam 0.29 for 0.51, without the
// quasi-static row), so this test fails without that row.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "hil_squeeze.hpp"

namespace {

using pliant::hil::HilObject;
using pliant::hil::SqueezeOptions;

constexpr double kAgreement = 0.03;

// The objects of the HIL's reduced runs, soft to stiff.
std::vector<HilObject> reduced_run_objects() {
  const std::set<std::string> names = {"foam cylinder", "gel cube", "stiffening foam", "rubber cylinder", "egg"};
  std::vector<HilObject> chosen;
  for (const HilObject& object : pliant::hil::hil_objects()) {
    if (names.count(object.name) != 0) chosen.push_back(object);
  }
  return chosen;
}

TEST(HilOnlineOffline, OnlineEstimateAgreesWithOfflineAtTheEndOfTheSqueeze) {
  const std::vector<HilObject> objects = reduced_run_objects();
  ASSERT_EQ(objects.size(), 5u);
  std::printf("%-16s %5s %6s %5s  %-22s  %-22s  %6s\n", "object", "mm/s", "frames", "beta", "offline (alpha, steps)",
              "online (alpha, steps)", "diff");
  for (const double speed_m_per_s : {0.001, 0.02}) {
    for (const HilObject& object : objects) {
      SqueezeOptions options;
      options.speed_m_per_s = speed_m_per_s;
      const pliant::host::Recording recording = pliant::hil::record_squeeze(object, options);
      const pliant::OnlineDeformabilityConfig config =
          pliant::hil::hil_supervisor_config(object, pliant::hil::RigOptions{}).estimator;
      const pliant::hil::OnlineRun online = pliant::hil::run_online(recording, config);
      const pliant::host::EstimateReport offline = pliant::hil::run_offline(recording, false);
      const double difference = online.estimate.msm_beta - offline.result.msm_beta;
      std::printf("%-16s %5.0f %6d %5.2f  %5.3f (%4.2f, %d)%7s  %5.3f (%4.2f, %d)%7s  %+6.3f\n", object.name.c_str(),
                  1000 * speed_m_per_s, recording.frame_count(), object.object.msm_beta, offline.result.msm_beta,
                  offline.result.msm_alpha, offline.baseline.steps_per_frame(), "", online.estimate.msm_beta,
                  online.estimate.msm_alpha, online.estimate.steps_per_frame, "", difference);
      std::fflush(stdout);
      EXPECT_EQ(online.estimate.frames, static_cast<std::uint32_t>(recording.frame_count() - 1)) << object.name;
      EXPECT_LE(std::abs(difference), kAgreement)
          << object.name << " at " << 1000 * speed_m_per_s << " mm/s: online " << online.estimate.msm_beta
          << ", offline " << offline.result.msm_beta;
    }
  }
}

}  // namespace
