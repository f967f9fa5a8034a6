#include "pliant/host/replay/online_estimator.hpp"

#include <algorithm>
#include <vector>

#include "pliant/core/arena.hpp"
#include "pliant/host/msm_setup.hpp"

namespace pliant::host {

namespace detail {

class OnlineEstimatorBase {
 public:
  virtual ~OnlineEstimatorBase() = default;
  virtual Status update(const double* positions, double recorded_t_s, double dt_s) = 0;
  virtual OnlineDeformabilityEstimate estimate() const = 0;
  virtual void reset() = 0;
  virtual std::uint32_t rejected() const = 0;
  virtual std::uint32_t empty() const = 0;
};

}  // namespace detail

namespace {

template <int Dim>
class EstimatorOf final : public detail::OnlineEstimatorBase {
 public:
  using Vec = Eigen::Matrix<double, Dim, 1>;
  EstimatorOf(const Recording& recording, const OnlineDeformabilityConfig& config, double msm_alpha)
      : recording_(recording) {
    model_ = build_msm_model<Dim>(recording, MsmSetupOptions{});
    workspace_.resize(online_deformability_workspace_size(model_->model, config));
    Arena arena(workspace_.data(), workspace_.size());
    require_ok(online_deformability_init(arena, model_->model, base_params<Dim>(recording, msm_alpha), config, online_),
               "online estimator");
    const auto n = static_cast<std::size_t>(recording.particle_count);
    observed_.assign(n, Vec::Zero());
    driven_ids_.reserve(n);
    driven_targets_.reserve(n);
  }

  Status update(const double* positions, double recorded_t_s, double dt_s) override {
    for (std::size_t i = 0; i < observed_.size(); ++i) {
      for (int d = 0; d < Dim; ++d) observed_[i](d) = positions[i * Dim + static_cast<std::size_t>(d)];
    }
    driven_ids_.clear();
    driven_targets_.clear();
    for (const DrivenWindow& w : recording_.driven) {
      const Vec& p = observed_[static_cast<std::size_t>(w.id)];
      if (!w.active_at(recorded_t_s) || !p.allFinite()) continue;
      if (std::find(driven_ids_.begin(), driven_ids_.end(), w.id) != driven_ids_.end()) continue;
      driven_ids_.push_back(w.id);
      driven_targets_.push_back(p);
    }
    const MsmDrivenTargets<Dim, double> driven{driven_ids_.data(), driven_targets_.data(),
                                               static_cast<int>(driven_ids_.size())};
    return online_deformability_update(model_->model, online_, dt_s, driven, observed_.data());
  }
  OnlineDeformabilityEstimate estimate() const override { return online_deformability_estimate(online_); }
  void reset() override { online_deformability_reset(model_->model, online_); }
  std::uint32_t rejected() const override { return online_.rejected_frames; }
  std::uint32_t empty() const override { return online_.empty_frames; }

 private:
  const Recording& recording_;
  std::unique_ptr<HostMsmModel<Dim>> model_;
  std::vector<unsigned char> workspace_;  // the core estimator's memory, carved once
  OnlineDeformability<Dim, double> online_;
  std::vector<Vec> observed_;
  std::vector<int> driven_ids_;
  std::vector<Vec> driven_targets_;
};

}  // namespace

OnlineRecordingEstimator::OnlineRecordingEstimator(const Recording& recording, const OnlineDeformabilityConfig& config,
                                                   double msm_alpha) {
  if (recording.dimension == 2) {
    estimator_ = std::make_unique<EstimatorOf<2>>(recording, config, msm_alpha);
  } else {
    estimator_ = std::make_unique<EstimatorOf<3>>(recording, config, msm_alpha);
  }
}

OnlineRecordingEstimator::~OnlineRecordingEstimator() = default;

Status OnlineRecordingEstimator::update(const double* positions, double recorded_t_s, double dt_s) {
  return estimator_->update(positions, recorded_t_s, dt_s);
}
OnlineDeformabilityEstimate OnlineRecordingEstimator::estimate() const { return estimator_->estimate(); }
void OnlineRecordingEstimator::reset() { estimator_->reset(); }
std::uint32_t OnlineRecordingEstimator::rejected_frames() const { return estimator_->rejected(); }
std::uint32_t OnlineRecordingEstimator::empty_frames() const { return estimator_->empty(); }

}  // namespace pliant::host
