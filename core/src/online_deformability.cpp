#include "pliant/core/online_deformability.hpp"

#include <cmath>
#include <limits>

#include "pliant/core/curve_analysis.hpp"

namespace pliant {

template <int Dim, typename Scalar>
std::size_t online_deformability_workspace_size(const MsmModel<Dim, Scalar>& model,
                                                const OnlineDeformabilityConfig& config) noexcept {
  Arena measure;
  OnlineDeformability<Dim, Scalar> scratch;
  (void)online_deformability_init(measure, model, MsmParams<Dim, Scalar>{}, config, scratch);
  return measure.required_bytes();
}

template <int Dim, typename Scalar>
Status online_deformability_init(Arena& arena, const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& base,
                                 const OnlineDeformabilityConfig& config,
                                 OnlineDeformability<Dim, Scalar>& estimator) noexcept {
  estimator = OnlineDeformability<Dim, Scalar>{};
  if (!model.initialized()) return Status::not_initialized;
  if (config.candidates < 3 || !(config.forgetting > 0) || config.forgetting > 1) return Status::invalid_argument;
  OnlineDeformability<Dim, Scalar> e;
  e.candidates = config.candidates;
  e.params = base;
  e.forgetting = config.forgetting;
  const auto k = static_cast<std::size_t>(config.candidates);
  e.states = arena.carve<MsmState<Dim, Scalar>>(k);
  e.sum_squares = arena.carve<double>(k);
  bool ok = !arena.exhausted();
  for (int c = 0; c < config.candidates; ++c) {
    MsmState<Dim, Scalar> dummy;
    ok = msm_state_init(arena, model, e.states != nullptr ? e.states[c] : dummy) == Status::ok && ok;
  }
  if (!ok || arena.exhausted()) return Status::capacity_exceeded;
  estimator = e;
  online_deformability_reset(model, estimator);
  return Status::ok;
}

template <int Dim, typename Scalar>
void online_deformability_reset(const MsmModel<Dim, Scalar>& model,
                                OnlineDeformability<Dim, Scalar>& estimator) noexcept {
  PLIANT_ASSERT(estimator.initialized());
  for (int c = 0; c < estimator.candidates; ++c) {
    msm_state_reset(model, estimator.states[c]);
    estimator.sum_squares[c] = 0;
  }
  estimator.residual_count = 0;
  estimator.frames = 0;
}

template <int Dim, typename Scalar>
Status online_deformability_update(const MsmModel<Dim, Scalar>& model, OnlineDeformability<Dim, Scalar>& estimator,
                                   Scalar dt, const MsmDrivenTargets<Dim, Scalar>& driven,
                                   const Eigen::Matrix<Scalar, Dim, 1>* observed) noexcept {
  if (!estimator.initialized() || !model.initialized()) return Status::not_initialized;
  if (!std::isfinite(dt) || !(dt > Scalar(0)) || observed == nullptr) {
    ++estimator.rejected_frames;
    return Status::invalid_argument;
  }
  MsmParams<Dim, Scalar> params = estimator.params;
  MsmStepInput<Dim, Scalar> input;
  input.dt = dt;
  input.driven = driven;
  double frame_count = 0;
  for (int c = 0; c < estimator.candidates; ++c) {
    params.msm_beta = static_cast<Scalar>(static_cast<double>(c) / (estimator.candidates - 1));
    MsmState<Dim, Scalar>& state = estimator.states[c];
    const Status stepped = msm_step(model, params, input, state);
    if (stepped == Status::invalid_argument || stepped == Status::not_initialized) {
      ++estimator.rejected_frames;
      return Status::invalid_argument;
    }
    double frame_squares = 0;
    frame_count = 0;
    for (int i = 0; i < model.particle_count; ++i) {
      if (model.fixed[i] != 0 || state.driven_now[i] != 0 || !observed[i].allFinite()) continue;
      frame_squares += (state.position[i] - observed[i]).template cast<double>().squaredNorm();
      frame_count += Dim;
    }
    estimator.sum_squares[c] = estimator.forgetting * estimator.sum_squares[c] + frame_squares;
  }
  estimator.residual_count = estimator.forgetting * estimator.residual_count + frame_count;
  ++estimator.frames;
  if (frame_count == 0) {
    ++estimator.empty_frames;
    return Status::no_observations;
  }
  return Status::ok;
}

template <int Dim, typename Scalar>
OnlineDeformabilityEstimate online_deformability_estimate(const OnlineDeformability<Dim, Scalar>& estimator) noexcept {
  OnlineDeformabilityEstimate out;
  out.frames = estimator.frames;
  out.msm_beta_std = std::numeric_limits<double>::infinity();
  if (!estimator.initialized() || estimator.residual_count < 2) return out;
  const int k = estimator.candidates;
  int best = 0;
  for (int c = 1; c < k; ++c) {
    if (estimator.sum_squares[c] < estimator.sum_squares[best]) best = c;
  }
  const double h = 1.0 / (k - 1);
  const int centre = best == 0 ? 1 : (best == k - 1 ? k - 2 : best);
  const ParabolaFit fit = fit_parabola(centre * h, h, estimator.sum_squares[centre - 1], estimator.sum_squares[centre],
                                       estimator.sum_squares[centre + 1]);
  const double vertex = fit.curvature > 0 ? fit.x : best * h;
  out.msm_beta = vertex < 0 ? 0 : (vertex > 1 ? 1 : vertex);
  const double s_min = fit.curvature > 0 ? std::max(fit.value, 0.0) : estimator.sum_squares[best];
  out.msm_beta_std = least_squares_std(s_min, fit.curvature, static_cast<long>(estimator.residual_count));
  out.unique_minimum = fit.curvature > 0 && single_basin(estimator.sum_squares, k);
  out.rms = std::sqrt(estimator.sum_squares[best] / estimator.residual_count);
  return out;
}

#define PLIANT_INSTANTIATE_ONLINE(DIM, SCALAR)                                                                       \
  template std::size_t online_deformability_workspace_size<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&,                \
                                                                        const OnlineDeformabilityConfig&) noexcept;  \
  template Status online_deformability_init<DIM, SCALAR>(                                                            \
      Arena&, const MsmModel<DIM, SCALAR>&, const MsmParams<DIM, SCALAR>&, const OnlineDeformabilityConfig&,         \
      OnlineDeformability<DIM, SCALAR>&) noexcept;                                                                   \
  template void online_deformability_reset<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&,                                \
                                                        OnlineDeformability<DIM, SCALAR>&) noexcept;                 \
  template Status online_deformability_update<DIM, SCALAR>(                                                          \
      const MsmModel<DIM, SCALAR>&, OnlineDeformability<DIM, SCALAR>&, SCALAR, const MsmDrivenTargets<DIM, SCALAR>&, \
      const Eigen::Matrix<SCALAR, DIM, 1>*) noexcept;                                                                \
  template OnlineDeformabilityEstimate online_deformability_estimate<DIM, SCALAR>(                                   \
      const OnlineDeformability<DIM, SCALAR>&) noexcept;
PLIANT_INSTANTIATE_ONLINE(2, float)
PLIANT_INSTANTIATE_ONLINE(2, double)
PLIANT_INSTANTIATE_ONLINE(3, float)
PLIANT_INSTANTIATE_ONLINE(3, double)
#undef PLIANT_INSTANTIATE_ONLINE

}  // namespace pliant
