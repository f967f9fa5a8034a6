// Builds core MSM objects from a Recording, in host (heap-owning) memory.
//
// The model follows the project-wide MSM defaults: rest = the recording's rest configuration,
// masses as the recording gives them, recording `fixed` ids pinned, every `driven` id drivable,
// one cluster per particle within 1.5x the median nearest-neighbour distance (unless
// `clusters` says otherwise). Host code: allocates, throws std::runtime_error naming the core
// status when the recording cannot define a model.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "pliant/core/msm.hpp"
#include "pliant/core/observations.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

/// Where the rest shape comes from when the recording has no mesh.
enum class RestSource {
  first_frame,   ///< frame 0, as recording-v1 defines it
  still_frames,  ///< mean of the leading frames before anything moves (frame 0 when none)
};

struct MsmSetupOptions {
  ClusterConfig clusters;
  double driven_mass_factor = 1.0;
  RestSource rest = RestSource::still_frames;
};

/// Leading frames in which the object is still at rest, and their per-particle mean.
///
/// The noise of a single frame is the largest error source in a fitted msm_beta (every frame
/// is compared against a model built on that frame's shape), and robots usually film an object
/// before touching it. Motion is detected against the recording's own noise, measured on the
/// declared `fixed` particles (robust: median absolute frame-to-frame change): the still phase
/// ends at the first frame where any particle has moved more than 5 noise standard deviations
/// from frame 0. Without fixed particles, with a mesh, or without such a phase, the result is
/// frame 0 alone (`frames` = 1).
struct StillRest {
  std::vector<double> positions;  ///< particle_count * dimension
  int frames = 1;                 ///< leading frames averaged
  double noise_std = 0;           ///< per-coordinate noise measured on fixed particles (0: unknown)
};
StillRest rest_from_still_frames(const Recording& recording);

/// An MSM model and the memory it lives in. Not copyable (the model points into `block`).
template <int Dim>
struct HostMsmModel {
  std::unique_ptr<unsigned char[]> block;
  MsmModel<Dim, double> model;
  std::vector<DrivenWindow> driven;  ///< the recording's driven windows
  int rest_frames = 1;               ///< frames averaged into the rest shape
  std::vector<double> rest;          ///< the rest shape used, particle_count * Dim
  double noise_std = 0;              ///< position noise measured on fixed particles (0: unknown)
};

/// Builds the model. With RestSource::still_frames the rest shape is rest_from_still_frames().
template <int Dim>
std::unique_ptr<HostMsmModel<Dim>> build_msm_model(const Recording& recording, const MsmSetupOptions& options);

/// Observation view over recording.positions (no copy; the recording must outlive it).
template <int Dim>
ObservationSequence<Dim, double> observations_of(const Recording& recording, const HostMsmModel<Dim>& model);

/// Base parameters from a recording: gravity when declared, else none.
template <int Dim>
MsmParams<Dim, double> base_params(const Recording& recording, double msm_alpha);

/// Throws std::runtime_error("<what>: <status name>") unless status is ok.
void require_ok(Status status, const char* what);

}  // namespace pliant::host
