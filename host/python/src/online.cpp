// pliant.OnlineEstimator: the core's online msm_beta estimator (pliant/core/online_deformability.hpp)
// on a recording's model, stepped frame by frame with NumPy arrays, exactly as `pliant replay`
// steps it (host/src/replay/replay_session.cpp): the model from the recording (rest shape, fixed
// particles, clusters), the recording's driven particles following their observed positions
// while their windows are active at the frame's recorded time.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "exit_status.hpp"
#include "pliant/core/arena.hpp"
#include "pliant/core/online_deformability.hpp"
#include "pliant/host/msm_setup.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::python {
namespace {

/// The estimator of one dimension, in memory this wrapper owns.
class Estimator {
 public:
  virtual ~Estimator() = default;
  /// positions: [particle_count * Dim], NaN unobserved. Returns the core's status.
  virtual Status update(double t_s, double dt_s, const double* positions) = 0;
  virtual OnlineDeformabilityEstimate estimate() const = 0;
  virtual void reset() = 0;
  virtual std::uint32_t rejected() const = 0;
  virtual std::uint32_t empty() const = 0;
};

template <int Dim>
class EstimatorOf final : public Estimator {
 public:
  using Vec = Eigen::Matrix<double, Dim, 1>;
  EstimatorOf(std::shared_ptr<const host::Recording> recording, const OnlineDeformabilityConfig& config,
              double msm_alpha)
      : recording_(std::move(recording)) {
    model_ = host::build_msm_model<Dim>(*recording_, host::MsmSetupOptions{});
    workspace_.resize(online_deformability_workspace_size(model_->model, config));
    Arena arena(workspace_.data(), workspace_.size());
    host::require_ok(online_deformability_init(arena, model_->model, host::base_params<Dim>(*recording_, msm_alpha),
                                               config, online_),
                     "online estimator");
    const auto n = static_cast<std::size_t>(recording_->particle_count);
    observed_.assign(n, Vec::Zero());
    driven_ids_.reserve(n);
    driven_targets_.reserve(n);
  }

  Status update(double t_s, double dt_s, const double* positions) override {
    for (std::size_t i = 0; i < observed_.size(); ++i) {
      for (int d = 0; d < Dim; ++d) observed_[i](d) = positions[i * Dim + static_cast<std::size_t>(d)];
    }
    driven_ids_.clear();
    driven_targets_.clear();
    for (const host::DrivenWindow& window : recording_->driven) {
      const Vec& p = observed_[static_cast<std::size_t>(window.id)];
      if (!window.active_at(t_s) || !p.allFinite()) continue;
      if (std::find(driven_ids_.begin(), driven_ids_.end(), window.id) != driven_ids_.end()) continue;
      driven_ids_.push_back(window.id);
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
  std::shared_ptr<const host::Recording> recording_;
  std::unique_ptr<host::HostMsmModel<Dim>> model_;
  std::vector<unsigned char> workspace_;  // the core estimator's memory, carved once
  OnlineDeformability<Dim, double> online_;
  std::vector<Vec> observed_;
  std::vector<int> driven_ids_;
  std::vector<Vec> driven_targets_;
};

struct OnlineSettings {
  int candidates = 21;
  int alpha_candidates = 3;
  int step_candidates = 3;
  int settled_row = 0;
  double msm_alpha = 1.0;
  double forgetting = 1.0;
};

// The replay's checks, in its words (UsageError: pliant.UsageError).
OnlineDeformabilityConfig online_config(const OnlineSettings& s) {
  if (s.candidates < 3) throw cli::UsageError("the online estimator needs at least 3 candidates");
  if (s.alpha_candidates < 1 || s.alpha_candidates > kMaxOnlineAlphaRows) {
    throw cli::UsageError("the online estimator takes 1 to " + std::to_string(kMaxOnlineAlphaRows) + " msm_alpha rows");
  }
  if (s.step_candidates < 1 || s.step_candidates > kMaxOnlineStepRows) {
    throw cli::UsageError("the online estimator takes 1 to " + std::to_string(kMaxOnlineStepRows) +
                          " rows of steps per frame");
  }
  if (s.settled_row < 0 || s.settled_row > kMaxEquilibriumIterations) {
    throw cli::UsageError("the quasi-static row takes 0 to " + std::to_string(kMaxEquilibriumIterations) +
                          " iterations per frame");
  }
  if (!(s.msm_alpha > 0 && s.msm_alpha <= 1)) throw cli::UsageError("msm_alpha must be in (0, 1]");
  if (!(s.forgetting > 0 && s.forgetting <= 1)) throw cli::UsageError("forgetting must be in (0, 1]");
  OnlineDeformabilityConfig config;
  config.candidates = s.candidates;
  config.alpha_candidates = s.alpha_candidates;
  config.step_candidates = s.step_candidates;
  config.equilibrium_iterations = s.settled_row;
  config.forgetting = s.forgetting;
  return config;
}

py::dict estimate_dict(const OnlineDeformabilityEstimate& e) {
  py::dict out;
  out["msm_beta"] = e.msm_beta;
  out["msm_beta_std"] = e.msm_beta_std;
  out["msm_alpha"] = e.msm_alpha;
  out["alpha_fitted"] = e.alpha_fitted;
  out["steps_per_frame"] = e.steps_per_frame;
  out["unique_minimum"] = e.unique_minimum;
  out["rms"] = e.rms;
  out["frames"] = e.frames;
  return out;
}

/// pliant.OnlineEstimator.
class OnlineEstimator {
 public:
  OnlineEstimator(const std::shared_ptr<host::Recording>& recording, const OnlineSettings& settings)
      : particle_count_(recording->particle_count), dimension_(recording->dimension) {
    const OnlineDeformabilityConfig config = online_config(settings);
    const std::shared_ptr<const host::Recording> shared = recording;
    py::gil_scoped_release release;  // init relaxes nothing but carves and resets every candidate
    if (dimension_ == 2) {
      estimator_ = std::make_unique<EstimatorOf<2>>(shared, config, settings.msm_alpha);
    } else {
      estimator_ = std::make_unique<EstimatorOf<3>>(shared, config, settings.msm_alpha);
    }
  }

  py::dict update(double t_s, double dt_s, py::handle positions) {
    const py::array_t<double> frame =
        real_array(positions, "positions", {particle_count_, dimension_}, "(n_particles, dim)");
    Status status = Status::ok;
    OnlineDeformabilityEstimate after;
    {
      py::gil_scoped_release release;
      const std::lock_guard<std::mutex> lock(mutex_);
      status = estimator_->update(t_s, dt_s, frame.data());
      after = estimator_->estimate();
    }
    py::dict out = estimate_dict(after);
    out["status"] = status_name(status);
    return out;
  }

  py::dict estimate() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return estimate_dict(estimator_->estimate());
  }

  void reset() {
    const std::lock_guard<std::mutex> lock(mutex_);
    estimator_->reset();
  }

  int particle_count() const { return particle_count_; }
  int dimension() const { return dimension_; }
  std::uint32_t rejected() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return estimator_->rejected();
  }
  std::uint32_t empty() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return estimator_->empty();
  }

 private:
  int particle_count_;
  int dimension_;
  std::mutex mutex_;
  std::unique_ptr<Estimator> estimator_;
};

const char* kDoc = R"doc(OnlineEstimator(recording, *, candidates=21, alpha_candidates=3, step_candidates=3,
settled_row=0, msm_alpha=1.0, forgetting=1.0)

msm_beta estimated frame by frame (the controller's online estimator, core/online_deformability),
on the MSM model of `recording` (its rest shape, fixed particles and clusters; its driven
particles follow their observed positions while their windows are active). The defaults are
`pliant replay`'s: 21 msm_beta candidates per model form, msm_alpha rows 0.3, 0.65, 1 at 1, 2 and
4 MSM steps per frame. alpha_candidates=1, step_candidates=1 holds msm_alpha at `msm_alpha` (the
replay's --msm-alpha); settled_row=N adds the quasi-static row (--settled-row N); forgetting in
(0, 1] weighs past frames. The wrapper owns the estimator's fixed memory; no allocation per frame
in the core.)doc";

const char* kUpdateDoc = R"doc(update(t, dt, positions) -> dict

One frame: t, its recorded time (s, decides which driven windows are active); dt, seconds since
the previous frame (the first frame of a recording only anchors dt: do not pass it); positions,
(n_particles, dim) float in the recording's length unit, NaN where unobserved. Returns the
estimate after the frame: msm_beta, msm_beta_std (inf until the error curve has curvature),
msm_alpha, alpha_fitted, steps_per_frame (0: the quasi-static row), unique_minimum, rms, frames,
and status ('ok'; 'invalid_argument' for a rejected frame, e.g. dt <= 0; 'no_observations'
when no free particle was observed). The GIL is released during the update.)doc";

}  // namespace

void bind_online(py::module_& module) {
  py::class_<OnlineEstimator>(module, "OnlineEstimator", kDoc)
      .def(py::init([](const std::shared_ptr<host::Recording>& recording, int candidates, int alpha_candidates,
                       int step_candidates, int settled_row, double msm_alpha, double forgetting) {
             if (!recording) throw py::type_error("recording must be a pliant.Recording");
             OnlineSettings settings{candidates, alpha_candidates, step_candidates, settled_row, msm_alpha, forgetting};
             return std::make_unique<OnlineEstimator>(recording, settings);
           }),
           py::arg("recording"), py::kw_only(), py::arg("candidates") = 21, py::arg("alpha_candidates") = 3,
           py::arg("step_candidates") = 3, py::arg("settled_row") = 0, py::arg("msm_alpha") = 1.0,
           py::arg("forgetting") = 1.0)
      .def("update", &OnlineEstimator::update, py::arg("t"), py::arg("dt"), py::arg("positions"), kUpdateDoc)
      .def("estimate", &OnlineEstimator::estimate, "The current estimate (as update returns it, without status).")
      .def("reset", &OnlineEstimator::reset, "Back to rest with no evidence (a new grasp).")
      .def_property_readonly("particle_count", &OnlineEstimator::particle_count)
      .def_property_readonly("dimension", &OnlineEstimator::dimension)
      .def_property_readonly("rejected_frames", &OnlineEstimator::rejected, "frames refused (bad dt, ...)")
      .def_property_readonly("empty_frames", &OnlineEstimator::empty, "frames with no free particle observed");
}

}  // namespace pliant::python
