// A squeeze of one HIL object at a constant closing speed, written as a recording, and the two
// msm_beta estimators run on it: the online one frame by frame (as `pliant replay` feeds it) and
// the offline one (`pliant estimate`) on the whole recording.
//
// The plant is the HIL's SimulatedGrasp (quasi-static: the object relaxes with up to 24 MSM
// steps every 1 ms control period) seen by its MockParticleObserver (30 Hz, noisy). The jaws
// start touching the object and close at the given speed by closure_fraction of its extent.
// The tool contact is recorded the way the HIL supervisor drives its estimator: an observed
// particle within contact_band spacings of a jaw plane is driven in that frame, its target the
// observed position moved onto the plane. The recording holds that target as the particle's
// position while it is driven, and one driven window per run of frames in which it is.
#pragma once

#include <cstdint>

#include "hil_rig.hpp"
#include "pliant/core/online_deformability.hpp"
#include "pliant/host/estimate.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::hil {

struct SqueezeOptions {
  double speed_m_per_s = 0.001;  ///< jaw closing speed (the width shrinks at this rate)
  double closure_fraction = 0.15;
  double camera_rate_hz = 30;
  double camera_noise_m = 3e-5;  ///< per coordinate
  double contact_band = 0.2;     ///< x model spacing
  int rest_frames = 4;           ///< frames before the jaws move
  std::uint64_t seed = 1;
};

/// The squeeze as a 3D recording in metres (frame 0 at rest). Throws std::runtime_error when
/// the plant or the camera cannot be set up.
host::Recording record_squeeze(const HilObject& object, const SqueezeOptions& options);

struct OnlineRun {
  OnlineDeformabilityEstimate estimate;  ///< after the last frame
  double update_cpu_us = 0;              ///< mean CPU time of one online_deformability_update
  std::size_t workspace_bytes = 0;
  int frames = 0;
  std::uint32_t unrelaxed = 0;  ///< quasi-static candidate frames that hit the iteration bound
};

/// The online estimator over the recording's frames 1.., driven by the windows active at each
/// frame (the model as `pliant replay` builds it).
OnlineRun run_online(const host::Recording& recording, const OnlineDeformabilityConfig& config);

/// `pliant estimate` with its defaults (the baseline's msm_alpha, steps per frame and cluster
/// radius chosen from the recording), without the input-noise refits; with `radius_auto` false
/// the cluster radius is held at the setup's (the model the online estimator runs).
host::EstimateReport run_offline(const host::Recording& recording, bool radius_auto);

}  // namespace pliant::hil
