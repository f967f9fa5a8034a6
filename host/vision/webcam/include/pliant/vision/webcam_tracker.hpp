// The webcam tracking pipeline: frames -> particles seeded on a grid -> advected by dense flow
// (webcam_advection.hpp) -> corrected by the core MSM-regularised tracker -> trajectories with
// per-frame observed flags, and the support and driven particles (webcam_roles.hpp).
//
// The correction (core/include/pliant/core/tracker.hpp, docs/tracker.md) runs inside the loop:
// each frame's observations are candidates; the tracker keeps those that agree with its MSM
// prediction or with their neighbours, follows kept ones exactly (observation_gain 1, so no lag
// and no bias on msm_beta), and moves the others (occluded, failed checks, outliers) with the
// shape matching of their clusters. The next frame is advected from the corrected positions, so
// a particle under an occluder does not ride along with it.
//
// The tracker's model is the particle grid as a free object: rest = the first frame's seeds,
// every particle of mass 1, clusters of each particle and its 8 nearest neighbours, no support
// (known only once the whole video has been seen), msm_alpha 1, and msm_beta =
// tracker_msm_beta, 0.5 by default: the middle of the range the MSM paper measured on foams
// (0.51 - 0.78). It only shapes the paths of particles while they are not seen; seen ones follow
// their observations whatever it is. The tool particle drives the prior while its observation is
// usable (without it the prior would smooth the deformation peak under the tool away and reject
// the observations that show it): the one options.driven names, or else the boundary particle
// that has moved farthest from its seed so far (at least 1 px).
//
// Units: pixels and seconds. Host code: allocates, throws InputError (webcam_error.hpp) for
// unusable input (see FrameReader, seed_particles, choose_roles) and std::runtime_error for
// internal faults. Not thread-safe.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pliant/core/deformability.hpp"
#include "pliant/core/tracker.hpp"
#include "pliant/vision/webcam_advection.hpp"
#include "pliant/vision/webcam_frames.hpp"
#include "pliant/vision/webcam_grid.hpp"
#include "pliant/vision/webcam_roles.hpp"

namespace pliant::vision::webcam {

struct TrackOptions {
  FlowMethod flow = FlowMethod::dis;
  AdvectionConfig advection;
  double tracker_msm_beta = 0.5;        ///< [0, 1]: the tracker's prior (see the top of this file)
  TrackerConfig tracker;                ///< core defaults; observation_gain 1 keeps observations exact
  SupportSpec support;                  ///< detected by default
  DrivenSpec driven;                    ///< detected by default
  ProgressCallback progress = nullptr;  ///< (context, frames done, frames expected or -1)
  void* progress_context = nullptr;
};

/// Trajectories of a tracked video. Per-frame arrays are frame-major: [frame * particles + id].
struct TrackResult {
  std::string source;  ///< the input as named
  cv::Size frame_size;
  double source_fps_hz = 0;
  double rate_hz = 0;                  ///< frames per second kept (the source's when not resampled)
  ParticleGrid grid;                   ///< the seeds (first frame)
  std::vector<double> times_s;         ///< frame times, s, from 0, strictly increasing
  std::vector<int> source_index;       ///< frame index in the source
  std::vector<cv::Point2d> tracked;    ///< tracker positions, px (every frame, every particle)
  std::vector<std::uint8_t> observed;  ///< 1: the tracker used an observation of it this frame
  std::vector<std::uint8_t> check;     ///< ObservationKind of the frame's candidate
  std::vector<std::uint8_t> status;    ///< TrackStatus after the frame
  std::vector<float> fb_error_px;      ///< NaN when not computed
  std::vector<float> similarity;       ///< NaN when not computed
  std::vector<double> motion_px;       ///< per particle: largest distance from its seed where seen
  ParticleRoles roles;
  TrackerCounters counters;
  TrackOptions options;  ///< as used (progress callback cleared)

  int frame_count() const { return static_cast<int>(times_s.size()); }
  int particle_count() const { return grid.size(); }
  std::size_t at(int frame, int id) const {
    return static_cast<std::size_t>(frame) * static_cast<std::size_t>(grid.size()) + static_cast<std::size_t>(id);
  }
};

/// Throws InputError naming the first option out of range.
void check_track_options(const TrackOptions& options);

/// Tracks every frame `reader` delivers (at least 2). The region and grid are applied to the
/// first frame. Throws InputError for unusable input (fewer than 2 frames included).
TrackResult track_particles(FrameReader& reader, const Region& region, const GridSpec& grid,
                            const TrackOptions& options);

}  // namespace pliant::vision::webcam
