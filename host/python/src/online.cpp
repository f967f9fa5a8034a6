// pliant.OnlineEstimator: the core's online msm_beta estimator (pliant/core/online_deformability.hpp)
// on a recording's model, stepped frame by frame with NumPy arrays: the estimator `pliant replay`
// steps (pliant/host/replay/online_estimator.hpp), which owns the core's fixed memory.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "exit_status.hpp"
#include "pliant/core/online_deformability.hpp"
#include "pliant/host/recording.hpp"
#include "pliant/host/replay/online_estimator.hpp"

namespace pliant::python {
namespace {

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
      : recording_(recording), particle_count_(recording->particle_count), dimension_(recording->dimension) {
    const OnlineDeformabilityConfig config = online_config(settings);
    py::gil_scoped_release release;  // builds the model and carves and resets every candidate
    estimator_ = std::make_unique<host::OnlineRecordingEstimator>(*recording_, config, settings.msm_alpha);
  }

  py::dict update(double t_s, double dt_s, py::handle positions) {
    const py::array_t<double> frame =
        real_array(positions, "positions", {particle_count_, dimension_}, "(n_particles, dim)");
    Status status = Status::ok;
    OnlineDeformabilityEstimate after;
    {
      py::gil_scoped_release release;
      const std::lock_guard<std::mutex> lock(mutex_);
      status = estimator_->update(frame.data(), t_s, dt_s);
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
    return estimator_->rejected_frames();
  }
  std::uint32_t empty() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return estimator_->empty_frames();
  }

 private:
  std::shared_ptr<const host::Recording> recording_;  // the estimator reads its driven windows
  int particle_count_;
  int dimension_;
  std::mutex mutex_;
  std::unique_ptr<host::OnlineRecordingEstimator> estimator_;
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
