// Locate step of `pliant diagnose` (docs/spec/diagnosis-v1.md "location"; method:
// /work/shared/design/DIAGNOSIS.md, procedure step 3 and the signature table): where and when
// the baseline residual concentrates, and the dimensionless signature numbers that point at an
// effect.
//
// Units and conventions
// - Positions and residuals in the recording's length unit, times in seconds. noise_std is the
//   per-coordinate noise std (estimate_noise_std); the noise mean square of one Euclidean
//   residual |r|^2 is therefore dimension * noise_std^2.
// - noise_std <= 0 (or NaN) means "noise-free": it is replaced by a floor of 1e-9 times the
//   largest residual magnitude (locate_mismatch) or of the object size (the signatures), so
//   round-off is never located and nothing divides by zero.
// - "Clearly above noise" for a mean square ms over `samples` residual vectors means
//   ms > dimension * noise_std^2 * max(min_ratio^2, 1 + z * sqrt(2 / (samples * dimension))):
//   above min_ratio times the noise rms AND z standard errors above the noise mean square.
//
// Degenerate input (0 frames, 0 particles, all NaN, no fixed or driven particles, empty
// location): no function crashes or returns NaN; locate_mismatch returns an empty Location
// (t_start = t_end = 0) and every signature returns 0. Functions throw std::invalid_argument
// when array sizes disagree with the recording / field (frame_times_s size, simulated size,
// field shape, location ids out of range).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "pliant/host/diagnose/diagnosis.hpp"
#include "pliant/host/diagnose/residual_field.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

struct LocateOptions {
  double min_ratio = 1.5;        ///< "clearly above": rms above min_ratio * noise rms ...
  double z = 3.0;                ///< ... and mean square z standard errors above the noise
  double energy_fraction = 0.8;  ///< located particles cover this share of the excess energy
  int bridge_frames = 2;         ///< runs separated by at most this many frames are joined
};

/// Particles: each particle's excess energy is (rms_i^2 - dim * noise^2) * observed_frames_i
/// (0 when negative). Candidates are particles whose rms is clearly above noise; taken in
/// decreasing excess energy until they hold energy_fraction of the total excess energy of all
/// particles (all candidates when they hold less). Returned ascending.
/// Window: per-frame mean square of the located particles; frames where it is clearly above
/// noise form runs (gaps up to bridge_frames bridged); the run with the largest excess energy
/// gives t_start/t_end (times of its first and last frame). When no frame is clearly above
/// noise the window spans every frame where a located particle is observed.
/// No particle clearly above noise: empty Location. frame_times_s: field.frame_count entries.
Location locate_mismatch(const ResidualField& field, const std::vector<double>& frame_times_s, double noise_std,
                         const LocateOptions& options = {});

/// Excess rms of the located particles over the last 20% of the frames after unloading,
/// divided by their peak excess rms (the largest mean square pooled over 5 consecutive
/// frames); in [0, 1] (1: the residual does not decay after unloading). Excess rms =
/// sqrt(mean square - dim * noise^2), counted only when clearly above noise (the tail: only
/// the z-test, with z = 4). Unloading frame = the latest over driven particles of (a) the frame after the
/// particle last differs from its final driven position by more than
/// max(3 * noise * sqrt(dim), 1% of its travel) and (b) the frame after its driven window
/// ends, when it ends inside the recording. No driven particle: the last 20% of the recording.
/// 0 when the location is empty, no frame is clearly above noise, or no frame follows unloading.
double persistence_after_unload(const Recording& recording, const ResidualField& field, const Location& location,
                                double noise_std);

/// Multiple correlation R in [0, 1] between the driver velocity along its main direction of
/// motion and the mean residual vector of the located particles, over frames (per-frame driver
/// velocity: 5-frame least-squares slope on real times, averaged over driven particles whose
/// window is active, 0 in frames with no active driver; means removed). R^2 is the share of the
/// driver-speed variance a linear function of the residual explains, so a residual along any
/// direction that follows the driver's speed counts. Returned only when significant
/// (frames * R^2 > 10 + 3 * dim; white noise: p < 1e-3), else 0; 0 with no location, no
/// driven particle, fewer than dim + 3 frames, or constant series.
double velocity_correlation(const Recording& recording, const ResidualField& field, const Location& location);

/// Excess rms motion of the declared fixed particles in the OBSERVED data about their rest
/// (each one's mean over its first up to 10 observed frames), divided by the noise rms
/// noise * sqrt(dim): sqrt(max(0, ms - E_noise[ms])) / (noise * sqrt(dim)), where E_noise[ms]
/// accounts exactly for the noise of the rest estimate. 0 unless ms is 4 standard deviations
/// above E_noise[ms] (variance including the rest error each particle's samples share; the
/// statistic is skewed, 4 gives about 3e-4 false alarms on white noise); 0 without fixed
/// particles. A support sliding with rms s per axis gives
/// about s / noise.
double support_motion(const Recording& recording, double noise_std);

/// Model r(frame, i) = d_i * c_frame * u: one unit direction u shared by all particles and
/// frames, magnitude proportional to d_i, the distance of particle i's rest position from the
/// nearest fixed particle (the nearest driven one when nothing is fixed), with a free amplitude
/// c per frame. fraction = (energy explained - its expectation under white noise) / (residual
/// energy - noise energy), in [0, 1]; 0 unless the residual energy is clearly above noise.
/// direction = u (dimension entries, oriented along the mean drift), zeros when fraction is 0.
/// Rest positions: recording.rest_positions when complete, else each particle's first
/// observed position.
struct UniformDrift {
  double fraction = 0;
  std::vector<double> direction;
};
UniformDrift uniform_drift(const Recording& recording, const ResidualField& field, double noise_std);

/// Load = mean displacement of the active driven particles from their rest; its direction l is
/// taken at the largest amplitude A. s = residual of the located particles projected on l,
/// averaged over (frame, particle) pairs separately for small load (0.1 A < |load| <= 0.5 A)
/// and large load (|load| > 0.75 A). When both means differ from 0 by more than 3 standard
/// errors (noise / sqrt(pairs)) and have opposite signs, returns min(|s_small|, |s_large|) /
/// max(|s_small|, |s_large|) in (0, 1]; otherwise 0 (also when A <= 3 * noise * sqrt(dim)).
double load_sign_change(const Recording& recording, const ResidualField& field, const Location& location,
                        double noise_std);

/// Lag in SECONDS maximising the normalised cross-correlation between observed and simulated
/// velocities (5-frame least-squares slopes on real times) of the located particles (the
/// driven ones when the location is empty, else all), over integer frame lags up to a quarter
/// of the recording, refined by a parabola and converted with the median frame interval.
/// Positive: the observation lags the simulation (observed(t + lag) matches simulated(t)).
/// A non-zero integer lag is kept only when its (unnormalised) cross-correlation beats lag 0 by
/// 3 standard deviations of the exact noise of that difference (position noise noise_std
/// through the slope filter), else the lag is 0 plus the parabola offset (|offset| <= half a
/// frame): a constant-velocity ramp times itself only at its ends, so at low velocity-to-noise
/// ratio a lag of one or two frames is not distinguishable from 0. Returns exactly 0 when the
/// peak correlation is not positive and significant (peak * sqrt(samples) <= 3), when there is
/// no motion, or with fewer than 3 frames. simulated: same layout and size as
/// recording.positions.
double time_shift(const Recording& recording, const std::vector<double>& simulated, const Location& location,
                  double noise_std);

/// All signatures: "persistence_after_unload", "velocity_correlation", "support_motion",
/// "uniform_drift" (+ "uniform_drift_x", "uniform_drift_y" and, in 3D, "uniform_drift_z" for the
/// direction), "load_sign_change" (dimensionless) and "time_shift" (seconds).
std::map<std::string, double> residual_signatures(const Recording& recording, const std::vector<double>& simulated,
                                                  const ResidualField& field, const Location& location,
                                                  double noise_std);
/// Same, building the field (recording.positions - simulated) and the location itself.
std::map<std::string, double> residual_signatures(const Recording& recording, const std::vector<double>& simulated,
                                                  double noise_std);

}  // namespace pliant::host
