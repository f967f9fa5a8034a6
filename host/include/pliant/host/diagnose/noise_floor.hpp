// Model-independent measurement-noise estimate for a recording (docs/spec/diagnosis-v1.md,
// "noise_rms"; method: /work/shared/design/DIAGNOSIS.md, procedure step 1).
//
// Contract
// - Returns the standard deviation of the position noise of ONE coordinate, in the recording's
//   length_unit, measured from the tracks themselves: no model, no fixed particles required.
// - Method: for every particle, axis and observed frame k, a cubic polynomial in time (real
//   timestamps, so uneven sampling is exact) is least-squares fitted to the observed samples of
//   that track in the 7-frame window around k (shifted inward at the ends; NaN samples skipped,
//   degree lowered to (samples - 2) when fewer than 5 remain, at least 3 samples needed). The
//   residual y_k - fit(t_k) of white noise with std s has std s * sqrt(1 - H_kk) (H the hat
//   matrix of that window), so residual / sqrt(1 - H_kk) is a unit-gain noise sample. The
//   result is 1.4826 * median(|normalised residual|) over all samples, which ignores the few
//   samples where motion is not locally cubic (tool start/stop). Smooth motion at 30-60 Hz
//   leaks well under 1e-5 of the particle spacing.
// - Degenerate input: returns exactly 0 (never NaN) when no track has a window with 3 observed
//   samples (0, 1 or 2 frames, all-NaN tracks, no particles) and when the tracks are exactly
//   polynomial (noise-free).
// - Throws std::invalid_argument when positions.size() != frames * particle_count * dimension
//   or dimension < 1 or particle_count < 0.
#pragma once

#include "pliant/host/recording.hpp"

namespace pliant::host {

/// Per-coordinate position noise std of `recording` (length_unit); 0 when unmeasurable.
double estimate_noise_std(const Recording& recording);

}  // namespace pliant::host
