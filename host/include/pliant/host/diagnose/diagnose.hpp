// `pliant diagnose`: where the elastic MSM baseline disagrees with a recording, which physics
// it left out, that physics modelled and the fit shown to improve (docs/spec/diagnosis-v1.md,
// method in shared DIAGNOSIS.md, summarised in docs/diagnose.md).
//
// Procedure
// 1. Frames are split into interleaved blocks; odd blocks are held out of every fit and every
//    rms reported is measured on them.
// 2. Baseline: the model form a user would fit (msm_alpha held or fitted, steps per frame,
//    cluster radius: estimate's selection), then msm_beta (and msm_alpha) on the fitting frames.
//    Noise: measured from the recording alone.
// 3. Locate: residual field of the baseline, the particles and window where it concentrates,
//    and the signature statistics.
// 4. Every catalogued effect (effects.hpp) is refitted with msm_beta through the simulator: a
//    grid over the parameters whose response is flat near the null, msm_beta profiled out at
//    each grid point, then fit_least_squares (least_squares_fit.hpp, Ceres).
// 5. Select (selection.hpp): an effect is named only when its held-out rms improves clearly on
//    the baseline, its BIC gain is >= 10, a parameter is >= 3 standard deviations from its
//    null, it explains three quarters of the misfit beyond the noise, the baseline misfit
//    stands clearly above the noise floor and the choice holds under a block bootstrap of the
//    held-out frames; otherwise `consistent` or `unknown`.
// options.model == "fem" runs the same pipeline (the internal engine.hpp) on the corotational
// linear FEM baseline (fem_diagnose.hpp), which also compares forces and adds force_rms to the
// document.
// Host code: allocates, throws std::runtime_error with one line when a recording cannot be
// diagnosed (too few frames, nothing moves, nothing observed).
#pragma once

#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "pliant/host/diagnose/diagnosis.hpp"
#include "pliant/host/estimate.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

struct DiagnoseOptions {
  std::string model = "msm";  ///< "msm" or "fem" (fem_diagnose.hpp: needs a 3D recording with a mesh)
  /// FEM only: "auto" (quasi-static when the loading is slow against the lowest natural period),
  /// "quasi_static" or "dynamic".
  std::string fem_time = "auto";
  /// FEM quasi-static only: solve every k-th frame (0: automatic, at most about 40 solved frames).
  int fem_frame_stride = 0;
  /// Worker threads for the candidate fits, MSM and FEM (0: one per hardware thread, at most
  /// one per effect). The diagnosis does not depend on it. (The MSM baseline's selection of
  /// the model form runs its independent variants on one thread per hardware thread.)
  int threads = 0;
  /// MSM: the baseline's msm_alpha and steps per frame, as `pliant estimate` chooses them
  /// (docs/estimation.md): automatic selection, always fitted, or held at msm_alpha.
  AlphaMode alpha = AlphaMode::automatic;
  double msm_alpha = 1.0;              ///< (0, 1]: the held value
  int steps_per_frame = 0;             ///< 0: chosen as estimate chooses it (estimate.hpp); else held (1..64)
  bool cluster_radius_auto = true;     ///< also try auto_cluster_radii (else held)
  double cluster_radius_factor = 1.5;  ///< held value, and the first the automatic choice tries
  int holdout_block_frames = 0;        ///< 0: about a tenth of a second of frames (at least 3)
  /// Progress (stage name, done, total); may be empty.
  std::function<void(const std::string&, int, int)> progress;
};

struct DiagnoseResult {
  Diagnosis diagnosis;
  DiagnosisEvidence evidence;
  double runtime_s = 0;
};

DiagnoseResult diagnose_recording(const Recording& recording, const DiagnoseOptions& options);

/// The pliant-diagnosis v1 document.
nlohmann::json diagnosis_json(const Diagnosis& diagnosis);

/// A few lines for a terminal.
std::string diagnosis_summary(const Diagnosis& diagnosis, const std::string& length_unit);

}  // namespace pliant::host
