// Output-error residual field: observed minus simulated positions, per frame, particle and axis
// (docs/spec/diagnosis-v1.md; DiagnosisEvidence::residual_* in diagnosis.hpp).
//
// Contract
// - Inputs are frame-major [(frame * particle_count + id) * dimension + axis] arrays in the
//   recording's length unit, NaN where unobserved. frame_count is size / (particle_count *
//   dimension) (0 when particle_count is 0).
// - A (frame, particle) pair is observed when every coordinate of BOTH arrays is finite; its
//   residual is observed - simulated; otherwise all its residual coordinates are NaN.
// - The summaries never return NaN: an rms over no observed pair is 0 and the matching
//   *_samples entry is 0. Only residual_magnitudes keeps NaN for unobserved pairs, as
//   DiagnosisEvidence requires.
// - make_residual_field throws std::invalid_argument when the arrays differ in size, the size
//   is not a multiple of particle_count * dimension, dimension < 1, or particle_count < 0 (or
//   data is given for zero particles). Mask arguments must have one entry per particle or per
//   frame (else std::invalid_argument).
#pragma once

#include <cstddef>
#include <vector>

namespace pliant::host {

struct ResidualField {
  int frame_count = 0;
  int particle_count = 0;
  int dimension = 2;
  std::vector<double> residual;  ///< frame-major obs - sim, NaN where unobserved

  std::size_t index(int frame, int id) const {
    return (static_cast<std::size_t>(frame) * static_cast<std::size_t>(particle_count) + static_cast<std::size_t>(id)) *
           static_cast<std::size_t>(dimension);
  }
  const double* at(int frame, int id) const { return residual.data() + index(frame, id); }
  bool observed(int frame, int id) const;        ///< residual of the pair is finite
  double squared_norm(int frame, int id) const;  ///< |r|^2, NaN when unobserved
};

/// Residual observed - simulated of two frame-major arrays of the same size.
ResidualField make_residual_field(const std::vector<double>& observed, const std::vector<double>& simulated,
                                  int particle_count, int dimension);

/// Per particle: sqrt(mean over its observed frames of |r|^2) (frame_mask, when given: only
/// frames with a non-zero entry). particle_count entries; 0 for a never-observed particle.
std::vector<double> particle_rms(const ResidualField& field, const std::vector<unsigned char>* frame_mask = nullptr);
/// Per particle: number of observed frames counted by particle_rms.
std::vector<int> particle_samples(const ResidualField& field, const std::vector<unsigned char>* frame_mask = nullptr);

/// Per frame: sqrt(mean over its observed particles of |r|^2) (particle_mask, when given: only
/// particles with a non-zero entry). frame_count entries; 0 for a frame with no such particle.
std::vector<double> frame_rms(const ResidualField& field, const std::vector<unsigned char>* particle_mask = nullptr);
/// Per frame: number of observed particles counted by frame_rms.
std::vector<int> frame_samples(const ResidualField& field, const std::vector<unsigned char>* particle_mask = nullptr);

/// Frame-major |r| map [frame * particle_count + id] for DiagnosisEvidence::residual_*; NaN
/// where unobserved.
std::vector<double> residual_magnitudes(const ResidualField& field);

}  // namespace pliant::host
