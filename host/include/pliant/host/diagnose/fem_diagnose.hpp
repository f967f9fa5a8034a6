// `pliant diagnose --model fem`: the diagnosis procedure of diagnose.hpp on the corotational
// linear FEM baseline (docs/diagnose.md, section "--model fem").
//
// Baseline: one homogeneous Young's modulus fitted (poisson_ratio and density as the recording
// declares, else the defaults of fem_recording.hpp), fixed nodes pinned, driven nodes
// prescribed, gravity only if declared, no damping beyond the declared one. Quasi-static (a
// static solve per solved frame) when the loading time scale is at least 10 lowest natural
// periods or no node is free to vibrate, else dynamic (one Newmark step per frame). Residuals:
// positions of observed free nodes whitened by their noise floor, and the net reaction over
// wrench.applied_to against the measured wrench force (frames whose wrench is a measurement,
// fem_model_run.hpp), whitened by a force noise measured from the wrench stream itself.
// Candidate effects are fitted on DiagnoseOptions::threads worker threads (one simulator each);
// the result does not depend on the thread count.
//
// Host code: allocates, throws std::runtime_error with one line when a recording cannot be
// diagnosed with the FEM (not 3D, not in metres, no mesh, too few frames, nothing compared).
#pragma once

#include "pliant/host/diagnose/diagnose.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

/// Per-component noise std (N) of the wrench force stream: for every component that is not
/// constant, local cubic fits over 7 consecutive samples (real times), each residual scaled by
/// its exact noise gain 1 / sqrt(1 - H_kk), then 1.4826 * median |scaled residual| over all
/// components. 0 when there are fewer than 5 samples or the stream is exactly cubic.
double estimate_force_noise_std(const Recording& recording);

/// The FEM diagnosis (options.model is ignored).
DiagnoseResult diagnose_recording_fem(const Recording& recording, const DiagnoseOptions& options);

}  // namespace pliant::host
