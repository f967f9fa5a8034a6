// Held-out frames and the output-error rms of docs/spec/diagnosis-v1.md ("improvement" is
// computed on frames held out from fitting; "rms" is the root mean square of the position
// residual over observed (particle, frame) pairs, in the recording's length unit).
//
// Contract
// - interleaved_holdout(frame_count, block_frames): frame_count entries; frames are cut into
//   consecutive blocks of block_frames frames (the last block may be shorter) alternating
//   fit, held-out, fit, held-out, ...; the FIRST block is for fitting (so frame 0, the rest
//   shape, is always a fitting frame). Entry 1 = held out, 0 = fitting. frame_count <= 0
//   gives an empty vector. Throws std::invalid_argument when block_frames < 1.
// - residual_rms(...): arrays are frame-major [(frame * particle_count + id) * dimension +
//   axis]. Over every (particle, frame) pair with frame_mask[frame] == wanted (and, when
//   particle_mask is given, particle_mask[id] != 0) where all coordinates of both arrays are
//   finite, it returns sqrt(mean of |observed - simulated|^2), the squared EUCLIDEAN error of
//   the pair averaged over pairs (not over coordinates). A pair with NaN/inf in either array is
//   skipped. Returns 0 (never NaN) when no pair qualifies, including empty arrays and
//   particle_count == 0. Throws std::invalid_argument when observed and simulated differ in
//   size, the size is not a multiple of particle_count * dimension, frame_mask does not have
//   one entry per frame, particle_mask does not have particle_count entries, or dimension < 1.
#pragma once

#include <vector>

namespace pliant::host {

/// Alternating fit/held-out blocks; 1 marks a held-out frame; the first block is fitting.
std::vector<unsigned char> interleaved_holdout(int frame_count, int block_frames);

/// Root mean square Euclidean position error over observed (particle, frame) pairs selected by
/// frame_mask == wanted and the optional particle_mask; 0 when none qualifies.
double residual_rms(const std::vector<double>& observed, const std::vector<double>& simulated, int particle_count,
                    int dimension, const std::vector<unsigned char>& frame_mask, unsigned char wanted,
                    const std::vector<unsigned char>* particle_mask = nullptr);

/// An effect is named only when it explains at least this share of the baseline's held-out
/// misfit beyond the noise (docs/diagnose.md, step 6).
inline constexpr double min_explained_share = 0.75;

/// Share of the baseline's held-out mean square beyond the noise that a fit removes:
/// 1 - max(0, fit^2 - noise^2) / (baseline^2 - noise^2), all three rms in one unit (or all
/// whitened, noise 1). 1 when the fit reaches the noise, 0 when it is no better than the
/// baseline, negative when worse; 0 when the baseline is already within the noise.
double explained_share(double baseline_rms, double fit_rms, double noise_rms);

}  // namespace pliant::host
