// Trajectory fit of estimate_dynamic.hpp: the forward simulation of a recording, a residual
// function that looks ahead along the optimiser's finite differences on spare threads, and the
// fit itself. The modal warm start is in estimate_dynamic_modal.cpp.
#include "pliant/host/fem/estimate_dynamic.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <deque>
#include <functional>
#include <future>
#include <limits>
#include <memory>
#include <stdexcept>
#include <thread>
#include <utility>

#include <Eigen/Dense>

#include "trajectory_sensitivity.hpp"

namespace pliant::host::fem {
namespace {

std::size_t uz(int i) { return static_cast<std::size_t>(i); }
Eigen::Index ei(int i) { return static_cast<Eigen::Index>(i); }
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What the simulation needs to know about the recording, checked once.
struct Layout {
  int node_count = 0;
  std::vector<int> fixed;
  std::vector<int> driven;                       // the same in every frame
  std::vector<bool> constrained;                 // fixed or driven
  std::vector<std::vector<int>> residual_nodes;  // per frame: observed free nodes (frame 0 empty)
  int residual_count = 0;
  std::vector<int> observed_free_0;    // free nodes observed in frame 0
  std::vector<int> unobserved_free_0;  // free nodes not observed in frame 0
  bool use_wrench = false;
};

Layout make_layout(const FemRecordingProblem& problem) {
  const std::string label = "trajectory estimate (" + problem.name + "): ";
  Layout layout;
  layout.node_count = problem.mesh.point_count();
  const int n = layout.node_count;
  if (problem.frames.size() < 3) throw std::invalid_argument(label + "at least 3 frames are needed");
  layout.fixed = problem.fixed_nodes;
  layout.driven = problem.frames.front().driven_nodes;
  for (const FemFrame& frame : problem.frames) {
    if (frame.driven_nodes != layout.driven) {
      throw std::invalid_argument(label + "the set of driven nodes must be the same in every frame");
    }
    if (frame.observed_position_m.size() != 3 * ei(n)) throw std::invalid_argument(label + "frame size mismatch");
  }
  layout.constrained.assign(uz(n), false);
  for (int node : layout.fixed) layout.constrained[uz(node)] = true;
  for (int node : layout.driven) layout.constrained[uz(node)] = true;
  layout.residual_nodes.resize(problem.frames.size());
  for (std::size_t f = 1; f < problem.frames.size(); ++f) {
    for (int node : problem.frames[f].observed_nodes) {
      if (!layout.constrained[uz(node)]) layout.residual_nodes[f].push_back(node);
    }
    layout.residual_count += 3 * static_cast<int>(layout.residual_nodes[f].size());
  }
  if (layout.residual_count == 0) throw std::invalid_argument(label + "no free node is observed after frame 0");
  std::vector<bool> observed0(uz(n), false);
  for (int node : problem.frames.front().observed_nodes) observed0[uz(node)] = true;
  for (int node = 0; node < n; ++node) {
    if (layout.constrained[uz(node)]) continue;
    (observed0[uz(node)] ? layout.observed_free_0 : layout.unobserved_free_0).push_back(node);
  }
  if (problem.has_wrench()) {
    layout.use_wrench = std::none_of(problem.applied_to.begin(), problem.applied_to.end(),
                                     [&](int node) { return layout.constrained[uz(node)]; });
  }
  return layout;
}

void check_simulation_options(const TrajectorySimulationOptions& options) {
  if (options.substeps < 1 || options.newton_iterations < 1) {
    throw std::invalid_argument("trajectory simulation: substeps and newton_iterations must be >= 1");
  }
}

// Thrown inside a simulation whose result is no longer wanted (SensitivityEvaluator).
struct Cancelled {};

// Outputs of one simulation; null pointers are not filled.
struct SimulationOutput {
  double* residuals = nullptr;                        // (sim - obs) * inverse_noise, frame-major
  std::vector<Eigen::VectorXd>* positions = nullptr;  // every frame
  // With sensitivities: d residual / d log(theta_j), residual-major (residual count x p).
  Eigen::MatrixXd* jacobian = nullptr;
  // With sensitivities: d position / d log(theta_j) per frame and parameter (frame 0 included).
  std::vector<std::vector<Eigen::VectorXd>>* position_sensitivities = nullptr;
  const std::atomic<bool>* cancel = nullptr;  // checked once per frame
};

// One thread's model and solvers; runs whole recordings. With `sensitivities` (non-empty), every
// run steps one substep per FemSolver::step call (so that runs with and without the Jacobian give
// the same residuals) and can propagate d x / d log(theta).
class Simulator {
 public:
  Simulator(const FemRecordingProblem& problem, const Layout& layout, const TrajectorySimulationOptions& options,
            std::vector<detail::SensitivityParameter> sensitivities = {})
      : problem_(problem),
        layout_(layout),
        options_(options),
        model_(problem.mesh, problem.material),
        dynamic_(model_, layout.fixed, layout.driven),
        per_substep_(!sensitivities.empty()),
        sensitivity_(std::move(sensitivities)) {
    if (!layout.unobserved_free_0.empty()) {
      fill_driven_ = layout.driven;
      fill_driven_.insert(fill_driven_.end(), layout.observed_free_0.begin(), layout.observed_free_0.end());
      fill_ = std::make_unique<FemSolver>(model_, layout.fixed, fill_driven_);
    }
  }

  // Simulates with the given material; fills residuals ((sim - obs) * inverse_noise, frame-major)
  // and/or positions (every frame). Throws std::runtime_error on solver failure.
  void run(const Eigen::Ref<const Eigen::VectorXd>& element_youngs_pa, double alpha, double beta, double inverse_noise,
           double* residuals, std::vector<Eigen::VectorXd>* positions) {
    SimulationOutput output;
    output.residuals = residuals;
    output.positions = positions;
    run(element_youngs_pa, alpha, beta, inverse_noise, output);
  }

  void run(const Eigen::Ref<const Eigen::VectorXd>& element_youngs_pa, double alpha, double beta, double inverse_noise,
           const SimulationOutput& output) {
    model_.set_youngs_modulus(element_youngs_pa);
    model_.set_rayleigh(alpha, beta);
    const std::vector<FemFrame>& frames = problem_.frames;
    const bool sensitive = output.jacobian != nullptr || output.position_sensitivities != nullptr;
    if (sensitive && !per_substep_) throw std::logic_error("trajectory simulation: no sensitivities configured");
    FemState state = dynamic_.rest_state();
    initial_state(state);
    if (sensitive) sensitivity_.start(fill_.get(), dynamic_, state.position_m);
    if (output.positions != nullptr) {
      output.positions->assign(frames.size(), Eigen::VectorXd());
      output.positions->front() = state.position_m;
    }
    if (output.jacobian != nullptr) output.jacobian->setZero(layout_.residual_count, sensitivity_.parameter_count());
    if (output.position_sensitivities != nullptr) {
      output.position_sensitivities->assign(frames.size(), {});
      keep_sensitivities((*output.position_sensitivities)[0]);
    }
    FemStepOptions step;
    step.integrator = options_.integrator;
    step.substeps = per_substep_ ? 1 : options_.substeps;
    step.newton_iterations = options_.newton_iterations;
    step.extrapolated_newton_start = options_.extrapolated_newton_start;
    std::size_t r = 0;
    for (std::size_t f = 1; f < frames.size(); ++f) {
      if (output.cancel != nullptr && output.cancel->load(std::memory_order_relaxed)) throw Cancelled{};
      const double dt = frames[f].time_s - frames[f - 1].time_s;
      const bool loaded = external_load(frames[f], state.position_m);
      if (per_substep_) {
        substeps(state, dt, frames[f].driven_position_m, loaded ? load_ : empty_, step, sensitive);
      } else {
        dynamic_.step(state, dt, frames[f].driven_position_m, loaded ? load_ : empty_, step);
      }
      if (output.positions != nullptr) (*output.positions)[f] = state.position_m;
      if (output.position_sensitivities != nullptr) keep_sensitivities((*output.position_sensitivities)[f]);
      for (int node : layout_.residual_nodes[f]) {
        for (int a = 0; a < 3; ++a, ++r) {
          const Eigen::Index i = 3 * ei(node) + a;
          if (output.residuals != nullptr) {
            output.residuals[r] = (state.position_m[i] - frames[f].observed_position_m[i]) * inverse_noise;
          }
          if (output.jacobian == nullptr) continue;
          for (int j = 0; j < sensitivity_.parameter_count(); ++j) {
            (*output.jacobian)(static_cast<Eigen::Index>(r), j) = sensitivity_.position(j)[i] * inverse_noise;
          }
        }
      }
    }
  }

 private:
  void keep_sensitivities(std::vector<Eigen::VectorXd>& out) const {
    out.clear();
    for (int j = 0; j < sensitivity_.parameter_count(); ++j) out.push_back(sensitivity_.position(j));
  }

  // One frame interval as options_.substeps calls of one substep each (the driven positions
  // interpolated linearly, as FemSolver::step does), carrying the sensitivities along.
  void substeps(FemState& state, double dt, const Eigen::VectorXd& driven_end, const Eigen::VectorXd& load,
                const FemStepOptions& step, bool sensitive) {
    driven_start_.resize(driven_end.size());
    for (std::size_t k = 0; k < layout_.driven.size(); ++k) {
      driven_start_.segment<3>(3 * static_cast<Eigen::Index>(k)) = state.position_m.segment<3>(3 * layout_.driven[k]);
    }
    const int count = options_.substeps;
    const double h = dt / count;
    for (int sub = 1; sub <= count; ++sub) {
      const double fraction = static_cast<double>(sub) / count;
      driven_target_ = driven_start_ + fraction * (driven_end - driven_start_);
      if (sensitive) {
        substep_start_ = state.position_m;
        substep_velocity_ = state.velocity_m_s;
      }
      dynamic_.step(state, h, driven_target_, load, step);
      if (sensitive) sensitivity_.substep(dynamic_, substep_start_, substep_velocity_, state.position_m, h);
    }
  }

  // The wrench of a frame as nodal loads, when it is an applied load (see the header).
  bool external_load(const FemFrame& frame, const Eigen::VectorXd& position_m) {
    if (!layout_.use_wrench || !frame.has_wrench) return false;
    Eigen::Vector3d rest_centroid = Eigen::Vector3d::Zero(), centroid = Eigen::Vector3d::Zero();
    for (int node : problem_.applied_to) {
      rest_centroid += model_.rest_position_m().segment<3>(3 * node);
      centroid += position_m.segment<3>(3 * node);
    }
    rest_centroid /= static_cast<double>(problem_.applied_to.size());
    centroid /= static_cast<double>(problem_.applied_to.size());
    const Eigen::Vector3d torque = frame.wrench_torque_nm + (rest_centroid - centroid).cross(frame.wrench_force_n);
    load_.setZero(model_.dof_count());
    add_spread_wrench(frame.wrench_force_n, torque, problem_.applied_to, position_m, load_);
    return true;
  }

  // Frame 0: observations, constraints, static fill of unobserved free nodes; velocity per options.
  void initial_state(FemState& state) {
    const FemFrame& first = problem_.frames.front();
    Eigen::VectorXd& x = state.position_m;
    x = model_.rest_position_m();
    for (int node : layout_.observed_free_0) x.segment<3>(3 * node) = first.observed_position_m.segment<3>(3 * node);
    for (std::size_t k = 0; k < layout_.driven.size(); ++k) {
      x.segment<3>(3 * layout_.driven[k]) = first.driven_position_m.segment<3>(3 * static_cast<Eigen::Index>(k));
    }
    state.velocity_m_s.setZero(model_.dof_count());
    if (options_.initial_velocity == InitialVelocity::finite_difference) {
      const FemFrame& f1 = problem_.frames[1];
      const FemFrame& f2 = problem_.frames[2];
      const double t0 = first.time_s, t1 = f1.time_s, t2 = f2.time_s;
      // Derivative at t0 of the quadratic through the three frames (Lagrange weights).
      const double w0 = (2 * t0 - t1 - t2) / ((t0 - t1) * (t0 - t2));
      const double w1 = (t0 - t2) / ((t1 - t0) * (t1 - t2));
      const double w2 = (t0 - t1) / ((t2 - t0) * (t2 - t1));
      for (int node : layout_.observed_free_0) {
        const Eigen::Vector3d p1 = f1.observed_position_m.segment<3>(3 * node);
        const Eigen::Vector3d p2 = f2.observed_position_m.segment<3>(3 * node);
        if (!p1.allFinite() || !p2.allFinite()) continue;
        state.velocity_m_s.segment<3>(3 * node) = w0 * x.segment<3>(3 * node) + w1 * p1 + w2 * p2;
      }
    }
    if (fill_) {
      const bool loaded = external_load(first, x);
      Eigen::VectorXd held(3 * ei(static_cast<int>(fill_driven_.size())));
      for (std::size_t k = 0; k < fill_driven_.size(); ++k)
        held.segment<3>(3 * static_cast<Eigen::Index>(k)) = x.segment<3>(3 * fill_driven_[k]);
      // Newton from the same start every time (observed nodes placed, the rest at rest), so a
      // simulation does not depend on which ones ran before it on this thread.
      FemStaticOptions static_options;
      static_options.max_iterations = 100;
      const FemStaticResult filled = fill_->solve_static(held, loaded ? load_ : empty_, static_options, x);
      if (!filled.converged) throw std::runtime_error("trajectory simulation: static fill of frame 0 did not converge");
      x = filled.position_m;
      if (options_.initial_velocity == InitialVelocity::finite_difference) {
        // Velocities of the filled nodes: the fill is (nearly) linear over a short time.
        constexpr double kDt = 1e-3;
        Eigen::VectorXd moved = held;
        for (std::size_t k = 0; k < fill_driven_.size(); ++k) {
          moved.segment<3>(3 * static_cast<Eigen::Index>(k)) +=
              kDt * state.velocity_m_s.segment<3>(3 * fill_driven_[k]);
        }
        const FemStaticResult later = fill_->solve_static(moved, loaded ? load_ : empty_, static_options, x);
        if (!later.converged)
          throw std::runtime_error("trajectory simulation: static fill of frame 0 did not converge");
        for (int node : layout_.unobserved_free_0) {
          state.velocity_m_s.segment<3>(3 * node) =
              (later.position_m.segment<3>(3 * node) - x.segment<3>(3 * node)) / kDt;
        }
      }
    }
    state.acceleration_m_s2.setZero(model_.dof_count());
    state.acceleration_valid = false;
    state.time_s = first.time_s;
  }

  const FemRecordingProblem& problem_;
  const Layout& layout_;
  TrajectorySimulationOptions options_;
  FemModel model_;
  FemSolver dynamic_;
  std::vector<int> fill_driven_;
  std::unique_ptr<FemSolver> fill_;
  Eigen::VectorXd load_;
  const Eigen::VectorXd empty_;
  bool per_substep_ = false;
  detail::TrajectorySensitivity sensitivity_;
  Eigen::VectorXd driven_start_, driven_target_, substep_start_, substep_velocity_;
};

// ---------------------------------------------------------------------------------------------
// Residual evaluation with look-ahead. fit_least_squares asks for the residuals at a point x and,
// when it needs the Jacobian, at x_j * exp(+h) and x_j * exp(-h) for j = 0, 1, ... in that order
// (log-scale parameters, h = FitOptions::difference_step, clipped at the bounds). While one
// simulation runs for the point asked, idle threads run the next points of that sequence; every
// result is cached, keyed by the parameter values (equal to 1e-12 relative: the optimiser's
// exp(log x + h) and ours differ in the last bit at most).

struct Evaluation {
  std::vector<double> values;
  std::vector<double> residuals;
  bool ok = false;
};

class LookAheadEvaluator {
 public:
  using Run = std::function<bool(Simulator&, const std::vector<double>&, std::vector<double>&)>;

  LookAheadEvaluator(std::vector<std::unique_ptr<Simulator>> simulators, Run run, std::vector<FitParameter> parameters,
                     double difference_step, bool central_differences)
      : simulators_(std::move(simulators)),
        busy_(simulators_.size(), false),
        run_(std::move(run)),
        parameters_(std::move(parameters)),
        step_(difference_step),
        central_(central_differences) {}

  ~LookAheadEvaluator() {
    for (Job& job : jobs_) job.future.wait();
  }
  LookAheadEvaluator(const LookAheadEvaluator&) = delete;
  LookAheadEvaluator& operator=(const LookAheadEvaluator&) = delete;

  // speculate = false: evaluate this point only (a one-off, not a step of the optimiser).
  bool evaluate(const std::vector<double>& values, std::vector<double>& residuals, bool speculate = true) {
    if (!speculate) {
      if (const Evaluation* done = find_done(values)) {
        residuals = done->residuals;
        return done->ok;
      }
      if (find_job(values) == jobs_.end()) {
        if (free_slot() < 0) collect(jobs_.begin());
        launch(values, free_slot());
      }
      collect(find_job(values));
      const Evaluation* done = find_done(values);
      residuals = done->residuals;
      return done->ok;
    }
    note_request(values);
    reap();
    if (const Evaluation* done = find_done(values)) {
      residuals = done->residuals;
      const bool ok = done->ok;
      look_ahead();
      return ok;
    }
    if (find_job(values) == jobs_.end()) {
      if (free_slot() < 0) collect(jobs_.begin());
      launch(values, free_slot());
    }
    look_ahead();
    const auto job = find_job(values);
    collect(job);
    const Evaluation* done = find_done(values);
    residuals = done->residuals;
    return done->ok;
  }

  int simulations() const { return simulations_; }

 private:
  struct Job {
    std::vector<double> values;
    int slot = 0;
    std::future<Evaluation> future;
  };

  static bool same(const std::vector<double>& a, const std::vector<double>& b) {
    for (std::size_t j = 0; j < a.size(); ++j) {
      if (std::abs(a[j] - b[j]) > 1e-12 * std::max(std::abs(a[j]), std::abs(b[j]))) return false;
    }
    return true;
  }

  const Evaluation* find_done(const std::vector<double>& values) const {
    for (const Evaluation& e : done_) {
      if (same(e.values, values)) return &e;
    }
    return nullptr;
  }

  std::deque<Job>::iterator find_job(const std::vector<double>& values) {
    return std::find_if(jobs_.begin(), jobs_.end(), [&](const Job& job) { return same(job.values, values); });
  }

  int free_slot() const {
    for (std::size_t s = 0; s < busy_.size(); ++s) {
      if (!busy_[s]) return static_cast<int>(s);
    }
    return -1;
  }

  void launch(const std::vector<double>& values, int slot) {
    busy_[uz(slot)] = true;
    ++simulations_;
    Simulator* simulator = simulators_[uz(slot)].get();
    const Run* run = &run_;
    Job job;
    job.values = values;
    job.slot = slot;
    job.future = std::async(std::launch::async, [simulator, run, values]() {
      Evaluation e;
      e.values = values;
      e.ok = (*run)(*simulator, values, e.residuals);
      return e;
    });
    jobs_.push_back(std::move(job));
  }

  void collect(std::deque<Job>::iterator job) {
    Evaluation e = job->future.get();
    busy_[uz(job->slot)] = false;
    jobs_.erase(job);
    done_.push_back(std::move(e));
    const std::size_t keep = 4 * parameters_.size() + 8;
    while (done_.size() > keep) done_.pop_front();
  }

  void reap() {
    for (auto it = jobs_.begin(); it != jobs_.end();) {
      if (it->future.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
        collect(it);
        it = jobs_.begin();
      } else {
        ++it;
      }
    }
  }

  // The optimiser's difference points around `base`, in its order (least_squares_fit.cpp: the
  // plus side, then the minus side; forward differences: the minus side only without a plus).
  std::vector<std::vector<double>> difference_points(const std::vector<double>& base) const {
    std::vector<std::vector<double>> points;
    for (std::size_t j = 0; j < parameters_.size(); ++j) {
      const FitParameter& p = parameters_[j];
      const double u = p.log_scale ? std::log(base[j]) : base[j];
      const double h = p.log_scale ? step_ : step_ * (p.upper - p.lower);
      const double hi = std::min(u + h, p.log_scale ? std::log(p.upper) : p.upper);
      const double lo = std::max(u - h, p.log_scale ? std::log(p.lower) : p.lower);
      const bool has_plus = hi > u;
      for (const double shifted : {hi, lo}) {
        if (shifted == u || (shifted == lo && !central_ && has_plus)) continue;
        points.push_back(base);
        points.back()[j] = p.log_scale ? std::exp(shifted) : shifted;
      }
    }
    return points;
  }

  // A point that is not one of the current base's difference points starts a new base.
  void note_request(const std::vector<double>& values) {
    for (std::size_t k = 0; k < sequence_.size(); ++k) {
      if (same(sequence_[k], values)) {
        position_ = static_cast<int>(k);
        return;
      }
    }
    sequence_ = difference_points(values);
    position_ = -1;
  }

  void look_ahead() {
    for (std::size_t k = uz(position_ + 1); k < sequence_.size(); ++k) {
      const int slot = free_slot();
      if (slot < 0) return;
      const std::vector<double>& point = sequence_[k];
      if (find_done(point) != nullptr || find_job(point) != jobs_.end()) continue;
      launch(point, slot);
    }
  }

  std::vector<std::unique_ptr<Simulator>> simulators_;
  std::vector<bool> busy_;
  Run run_;
  std::vector<FitParameter> parameters_;
  double step_;
  bool central_;
  std::deque<Job> jobs_;
  std::deque<Evaluation> done_;
  std::vector<std::vector<double>> sequence_;
  int position_ = -1;
  int simulations_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Residual evaluation with exact Jacobians (forward sensitivities). fit_least_squares asks for the
// residuals at a trial point and, once it accepts the point, for the Jacobian there. A Jacobian
// run also yields the residuals, so a trial point is simulated with its sensitivities at once:
// steps are mostly accepted, and a plain run beside it (on the other core) would only cost CPU
// time. A run at a point the optimiser has left is cancelled at its next frame.

struct SensitiveEvaluation {
  std::vector<double> values;
  std::vector<double> residuals;
  Eigen::MatrixXd jacobian;  // d residual / d log(theta); empty for a residual-only run
  bool with_jacobian = false;
  bool ok = false;
  bool cancelled = false;
};

class SensitivityEvaluator {
 public:
  using Run = std::function<bool(Simulator&, const std::vector<double>&, std::vector<double>&, Eigen::MatrixXd*,
                                 const std::atomic<bool>*)>;

  SensitivityEvaluator(std::vector<std::unique_ptr<Simulator>> simulators, Run run)
      : simulators_(std::move(simulators)), busy_(simulators_.size(), false), run_(std::move(run)) {}
  ~SensitivityEvaluator() {
    for (Job& job : jobs_) {
      job.cancel->store(true);
      job.future.wait();
    }
  }
  SensitivityEvaluator(const SensitivityEvaluator&) = delete;
  SensitivityEvaluator& operator=(const SensitivityEvaluator&) = delete;

  // Residuals at `values`. With `speculate` (a trial point of the optimiser, usually accepted,
  // and then its Jacobian is asked for next) the run carries the sensitivities: one run instead
  // of a plain one followed by a Jacobian run.
  bool evaluate(const std::vector<double>& values, std::vector<double>& residuals, bool speculate = true) {
    reap();
    if (const SensitiveEvaluation* done = find_done(values, false)) {
      residuals = done->residuals;
      return done->ok;
    }
    cancel_other(values);
    if (find_job(values, true) == jobs_.end() && find_job(values, false) == jobs_.end()) {
      launch(values, speculate, acquire_slot());
    }
    while (find_done(values, false) == nullptr) wait_any_at(values);
    const SensitiveEvaluation* done = find_done(values, false);
    residuals = done->residuals;
    return done->ok;
  }

  // Residuals and d residual / d log(theta) at `values`.
  bool jacobian(const std::vector<double>& values, std::vector<double>& residuals, Eigen::MatrixXd& jacobian) {
    reap();
    cancel_other(values);
    if (find_done(values, true) == nullptr && find_job(values, true) == jobs_.end()) {
      launch(values, true, acquire_slot());
    }
    while (find_done(values, true) == nullptr) wait_any_at(values);
    const SensitiveEvaluation* done = find_done(values, true);
    residuals = done->residuals;
    jacobian = done->jacobian;
    return done->ok;
  }

  int simulations() const { return simulations_; }

 private:
  struct Job {
    std::vector<double> values;
    bool with_jacobian = false;
    int slot = 0;
    std::shared_ptr<std::atomic<bool>> cancel;
    std::future<SensitiveEvaluation> future;
  };

  // Equal to 1e-12 relative: the optimiser's exp(log x) and the caller's x differ in the last bit.
  static bool same(const std::vector<double>& a, const std::vector<double>& b) {
    for (std::size_t j = 0; j < a.size(); ++j) {
      if (std::abs(a[j] - b[j]) > 1e-12 * std::max(std::abs(a[j]), std::abs(b[j]))) return false;
    }
    return true;
  }

  const SensitiveEvaluation* find_done(const std::vector<double>& values, bool need_jacobian) const {
    for (const SensitiveEvaluation& e : done_) {
      if (same(e.values, values) && (!need_jacobian || e.with_jacobian || !e.ok)) return &e;
    }
    return nullptr;
  }

  std::deque<Job>::iterator find_job(const std::vector<double>& values, bool with_jacobian) {
    return std::find_if(jobs_.begin(), jobs_.end(),
                        [&](const Job& job) { return job.with_jacobian == with_jacobian && same(job.values, values); });
  }

  int free_slot() const {
    for (std::size_t s = 0; s < busy_.size(); ++s) {
      if (!busy_[s]) return static_cast<int>(s);
    }
    return -1;
  }

  // A free slot, waiting for the oldest run when every thread is busy.
  int acquire_slot() {
    while (free_slot() < 0) collect(jobs_.begin());
    return free_slot();
  }

  // Runs at other points are no longer wanted (the optimiser moved on).
  void cancel_other(const std::vector<double>& values) {
    for (Job& job : jobs_) {
      if (!same(job.values, values)) job.cancel->store(true);
    }
  }

  void launch(const std::vector<double>& values, bool with_jacobian, int slot) {
    busy_[uz(slot)] = true;
    ++simulations_;
    Simulator* simulator = simulators_[uz(slot)].get();
    const Run* run = &run_;
    Job job;
    job.values = values;
    job.with_jacobian = with_jacobian;
    job.slot = slot;
    job.cancel = std::make_shared<std::atomic<bool>>(false);
    const std::atomic<bool>* cancel = job.cancel.get();
    job.future = std::async(std::launch::async, [simulator, run, values, with_jacobian, cancel]() {
      SensitiveEvaluation e;
      e.values = values;
      e.with_jacobian = with_jacobian;
      try {
        e.ok = (*run)(*simulator, values, e.residuals, with_jacobian ? &e.jacobian : nullptr, cancel);
      } catch (const Cancelled&) {
        e.cancelled = true;
      }
      return e;
    });
    jobs_.push_back(std::move(job));
  }

  void collect(std::deque<Job>::iterator job) {
    SensitiveEvaluation e = job->future.get();
    busy_[uz(job->slot)] = false;
    jobs_.erase(job);
    if (e.cancelled) return;
    done_.push_back(std::move(e));
    while (done_.size() > 8) done_.pop_front();
  }

  void reap() {
    for (auto it = jobs_.begin(); it != jobs_.end();) {
      if (it->future.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
        collect(it);
        it = jobs_.begin();
      } else {
        ++it;
      }
    }
  }

  // Waits until some run at `values` finishes (the caller checks whether it is the one needed).
  void wait_any_at(const std::vector<double>& values) {
    while (true) {
      for (auto it = jobs_.begin(); it != jobs_.end(); ++it) {
        if (same(it->values, values) &&
            it->future.wait_for(std::chrono::milliseconds(2)) == std::future_status::ready) {
          collect(it);
          return;
        }
      }
      if (std::none_of(jobs_.begin(), jobs_.end(), [&](const Job& job) { return same(job.values, values); })) {
        throw std::logic_error("trajectory estimate: no run at the requested point");
      }
      reap();
    }
  }

  std::vector<std::unique_ptr<Simulator>> simulators_;
  std::vector<bool> busy_;
  Run run_;
  std::deque<Job> jobs_;
  std::deque<SensitiveEvaluation> done_;
  int simulations_ = 0;
};

// The fit's view of either evaluator.
struct Evaluator {
  std::unique_ptr<LookAheadEvaluator> look_ahead;
  std::unique_ptr<SensitivityEvaluator> sensitive;

  bool evaluate(const std::vector<double>& values, std::vector<double>& residuals, bool speculate = true) {
    return sensitive ? sensitive->evaluate(values, residuals, speculate)
                     : look_ahead->evaluate(values, residuals, speculate);
  }
  // The starting point: with sensitivities, its Jacobian too.
  bool start(const std::vector<double>& values, std::vector<double>& residuals, bool speculate) {
    if (!sensitive) return look_ahead->evaluate(values, residuals, speculate);
    Eigen::MatrixXd jacobian;
    return sensitive->jacobian(values, residuals, jacobian);
  }
  FitResult fit(const std::vector<FitParameter>& parameters, int residual_count, const FitOptions& options) {
    const ResidualFunction residuals = [this](const std::vector<double>& values, std::vector<double>& out) {
      return evaluate(values, out);
    };
    if (!sensitive) return fit_least_squares(parameters, residual_count, residuals, options);
    const JacobianFunction jacobian = [this](const std::vector<double>& values, std::vector<double>& out,
                                             Eigen::MatrixXd& matrix) {
      if (!sensitive->jacobian(values, out, matrix)) return false;
      for (Eigen::Index j = 0; j < matrix.cols(); ++j) matrix.col(j) /= values[static_cast<std::size_t>(j)];
      return true;
    };
    return fit_least_squares(parameters, residual_count, residuals, jacobian, options);
  }
  int simulations() const { return sensitive ? sensitive->simulations() : look_ahead->simulations(); }
};

// Why forward sensitivities do not cover this configuration ("" when they do).
std::string sensitivities_unavailable(const TrajectoryEstimateOptions& options, const Layout& layout,
                                      bool material_map) {
  if (material_map) return "material map";
  if (options.simulation.integrator != FemIntegrator::newmark) return "backward Euler";
  if (options.simulation.initial_velocity != InitialVelocity::at_rest) return "initial velocity from the data";
  if (layout.use_wrench) return "measured wrench applied as a load";
  return "";
}

double rms(const std::vector<double>& r, double scale) {
  double s = 0;
  for (double x : r) s += x * x;
  return r.empty() ? 0.0 : std::sqrt(s / static_cast<double>(r.size())) * scale;
}

double inside(double value, double lower, double upper) {
  // Strictly inside the bounds (the optimiser's requirement), by a small relative margin.
  return std::clamp(value, lower * 1.001, upper / 1.001);
}

}  // namespace

std::vector<Eigen::VectorXd> simulate_trajectory(const FemRecordingProblem& problem,
                                                 const Eigen::Ref<const Eigen::VectorXd>& element_youngs_modulus_pa,
                                                 double rayleigh_alpha, double rayleigh_beta,
                                                 const TrajectorySimulationOptions& options) {
  check_simulation_options(options);
  const Layout layout = make_layout(problem);
  if (element_youngs_modulus_pa.size() != problem.mesh.tet_count()) {
    throw std::invalid_argument("simulate_trajectory: one modulus per tetrahedron expected");
  }
  Simulator simulator(problem, layout, options);
  std::vector<Eigen::VectorXd> positions;
  simulator.run(element_youngs_modulus_pa, rayleigh_alpha, rayleigh_beta, 1.0, nullptr, &positions);
  return positions;
}

TrajectorySensitivities simulate_trajectory_sensitivities(const FemRecordingProblem& problem, double youngs_modulus_pa,
                                                          double rayleigh_alpha, double rayleigh_beta,
                                                          const TrajectorySimulationOptions& options) {
  check_simulation_options(options);
  const Layout layout = make_layout(problem);
  TrajectoryEstimateOptions estimate;
  estimate.simulation = options;
  const std::string unavailable = sensitivities_unavailable(estimate, layout, false);
  if (!unavailable.empty()) throw std::invalid_argument("simulate_trajectory_sensitivities: " + unavailable);
  Simulator simulator(
      problem, layout, options,
      {detail::SensitivityParameter::log_youngs_modulus, detail::SensitivityParameter::log_rayleigh_alpha,
       detail::SensitivityParameter::log_rayleigh_beta});
  TrajectorySensitivities out;
  SimulationOutput output;
  output.positions = &out.position_m;
  output.position_sensitivities = &out.sensitivity_m;
  simulator.run(Eigen::VectorXd::Constant(problem.mesh.tet_count(), youngs_modulus_pa), rayleigh_alpha, rayleigh_beta,
                1.0, output);
  return out;
}

TrajectoryEstimate estimate_trajectory_parameters(const FemRecordingProblem& problem,
                                                  const TrajectoryEstimateOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  const std::string label = "trajectory estimate (" + problem.name + "): ";
  check_simulation_options(options.simulation);
  if (!(options.position_noise_m > 0) || !std::isfinite(options.position_noise_m)) {
    throw std::invalid_argument(label + "position_noise_m must be positive");
  }
  if (options.threads < 0) throw std::invalid_argument(label + "threads must be >= 0");
  const bool fit_modulus = options.estimate_youngs_modulus && !problem.is_known("youngs_modulus");
  const bool fit_alpha = options.estimate_rayleigh_alpha && !problem.is_known("rayleigh_alpha");
  const bool fit_beta = options.estimate_rayleigh_beta && !problem.is_known("rayleigh_beta");
  if (!fit_modulus && !fit_alpha && !fit_beta) throw std::invalid_argument(label + "nothing left to estimate");
  const Layout layout = make_layout(problem);

  // Material map (or one modulus).
  std::unique_ptr<MaterialMap> map;
  if (!options.control_points_m.empty()) {
    map = std::make_unique<MaterialMap>(problem.mesh, options.control_points_m, options.material_map);
  }
  const int k = map ? map->control_point_count() : 1;
  const int m = problem.mesh.tet_count();

  TrajectoryEstimate result;
  result.residual_count = layout.residual_count;
  result.control_points_m = options.control_points_m;

  // Starting values: the warm start where it measured something, else the options.
  double start_e =
      options.initial_youngs_modulus_pa > 0 ? options.initial_youngs_modulus_pa : problem.material.youngs_modulus_pa;
  double start_alpha = fit_alpha ? options.initial_rayleigh_alpha : problem.material.rayleigh_alpha;
  double start_beta = fit_beta ? options.initial_rayleigh_beta : problem.material.rayleigh_beta;
  if (!fit_modulus) start_e = problem.material.youngs_modulus_pa;
  if (options.warm_start) {
    result.warm_start = modal_warm_start(problem, options);
    if (fit_modulus && result.warm_start.modulus_matched) start_e = result.warm_start.youngs_modulus_pa;
    if (result.warm_start.damping_matched) {
      if (fit_alpha) start_alpha = result.warm_start.rayleigh_alpha;
      if (fit_beta) start_beta = result.warm_start.rayleigh_beta;
    }
  }

  const std::vector<double>& given_moduli = options.initial_control_youngs_modulus_pa;
  if (!given_moduli.empty()) {
    if (given_moduli.size() != static_cast<std::size_t>(k)) {
      throw std::invalid_argument(label + "initial_control_youngs_modulus_pa needs one value per control point");
    }
    for (double e : given_moduli) {
      if (!(e > 0) || !std::isfinite(e)) throw std::invalid_argument(label + "initial control moduli must be > 0");
    }
  }
  std::vector<FitParameter> parameters;
  if (fit_modulus) {
    for (int i = 0; i < k; ++i) {
      FitParameter p;
      p.name = map ? "youngs_modulus[" + std::to_string(i) + "]" : "youngs_modulus";
      p.lower = options.youngs_modulus_min_pa;
      p.upper = options.youngs_modulus_max_pa;
      p.initial = inside(given_moduli.empty() ? start_e : given_moduli[static_cast<std::size_t>(i)], p.lower, p.upper);
      parameters.push_back(p);
    }
  }
  if (fit_alpha) {
    parameters.push_back({"rayleigh_alpha", inside(start_alpha, options.rayleigh_alpha_min, options.rayleigh_alpha_max),
                          options.rayleigh_alpha_min, options.rayleigh_alpha_max, true});
  }
  if (fit_beta) {
    parameters.push_back({"rayleigh_beta", inside(start_beta, options.rayleigh_beta_min, options.rayleigh_beta_max),
                          options.rayleigh_beta_min, options.rayleigh_beta_max, true});
  }
  for (const FitParameter& p : parameters) {
    if (!(p.lower > 0) || !(p.lower < p.upper)) throw std::invalid_argument(label + "bad bounds for " + p.name);
    result.start_values.push_back(p.initial);
  }

  // Parameter vector -> material of the simulation.
  Eigen::VectorXd known_moduli = Eigen::VectorXd::Constant(m, problem.material.youngs_modulus_pa);
  if (static_cast<int>(problem.mesh.youngs_modulus.size()) == m) {
    known_moduli = Eigen::Map<const Eigen::VectorXd>(problem.mesh.youngs_modulus.data(), m);
  }
  const auto element_moduli = [&](const std::vector<double>& values) -> Eigen::VectorXd {
    if (!fit_modulus) return known_moduli;
    if (!map) return Eigen::VectorXd::Constant(m, values[0]);
    return map->element_values(std::vector<double>(values.begin(), values.begin() + k));
  };
  const int alpha_index = fit_alpha ? (fit_modulus ? k : 0) : -1;
  const int beta_index = fit_beta ? (fit_modulus ? k : 0) + (fit_alpha ? 1 : 0) : -1;
  const auto damping = [&](const std::vector<double>& values) {
    return std::make_pair(alpha_index >= 0 ? values[uz(alpha_index)] : problem.material.rayleigh_alpha,
                          beta_index >= 0 ? values[uz(beta_index)] : problem.material.rayleigh_beta);
  };
  const double inverse_noise = 1.0 / options.position_noise_m;
  const LookAheadEvaluator::Run run = [&](Simulator& simulator, const std::vector<double>& values,
                                          std::vector<double>& residuals) {
    try {
      const auto [alpha, beta] = damping(values);
      simulator.run(element_moduli(values), alpha, beta, inverse_noise, residuals.data(), nullptr);
      return true;
    } catch (const std::exception&) {
      return false;  // solver failure or inverted elements: the optimiser rejects the step
    }
  };
  int threads = options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::max(threads, 1);

  // Which Jacobian: forward sensitivities where they are exact to the linearised step.
  std::vector<detail::SensitivityParameter> sensitive;
  if (fit_modulus) sensitive.push_back(detail::SensitivityParameter::log_youngs_modulus);
  if (fit_alpha) sensitive.push_back(detail::SensitivityParameter::log_rayleigh_alpha);
  if (fit_beta) sensitive.push_back(detail::SensitivityParameter::log_rayleigh_beta);
  const std::string no_sensitivities = sensitivities_unavailable(options, layout, map != nullptr && fit_modulus);
  if (options.jacobian == TrajectoryJacobian::sensitivities && !no_sensitivities.empty()) {
    throw std::invalid_argument(label + "sensitivities are not available: " + no_sensitivities);
  }
  const bool use_sensitivities = options.jacobian != TrajectoryJacobian::finite_differences && no_sensitivities.empty();
  if (!use_sensitivities) sensitive.clear();
  result.jacobian = use_sensitivities ? "sensitivities"
                    : options.jacobian == TrajectoryJacobian::finite_differences
                        ? "finite differences (requested)"
                        : "finite differences (" + no_sensitivities + ")";

  // One evaluator per time window (continuation), each with its own simulators.
  const auto make_evaluator = [&](const FemRecordingProblem& window, const Layout& window_layout) {
    std::vector<std::unique_ptr<Simulator>> simulators;
    for (int t = 0; t < threads; ++t) {
      simulators.push_back(std::make_unique<Simulator>(window, window_layout, options.simulation, sensitive));
    }
    const int count = window_layout.residual_count;
    auto evaluator = std::make_unique<Evaluator>();
    if (use_sensitivities) {
      SensitivityEvaluator::Run sized = [&, count](Simulator& simulator, const std::vector<double>& values,
                                                   std::vector<double>& residuals, Eigen::MatrixXd* jacobian,
                                                   const std::atomic<bool>* cancel) {
        residuals.assign(uz(count), kNaN);
        try {
          const auto [alpha, beta] = damping(values);
          SimulationOutput output;
          output.residuals = residuals.data();
          output.jacobian = jacobian;
          output.cancel = cancel;
          simulator.run(element_moduli(values), alpha, beta, inverse_noise, output);
          return true;
        } catch (const std::exception&) {
          return false;
        }
      };
      evaluator->sensitive = std::make_unique<SensitivityEvaluator>(std::move(simulators), sized);
    } else {
      LookAheadEvaluator::Run sized = [run, count](Simulator& simulator, const std::vector<double>& values,
                                                   std::vector<double>& residuals) {
        residuals.assign(uz(count), kNaN);
        return run(simulator, values, residuals);
      };
      evaluator->look_ahead = std::make_unique<LookAheadEvaluator>(
          std::move(simulators), sized, parameters, options.fit.difference_step, options.fit.central_differences);
    }
    return evaluator;
  };

  // Continuation: fit the leading part of the record first (fewer periods, so a start that is off
  // in frequency cannot lock onto a neighbouring phase), then longer parts from there.
  const int frame_count = static_cast<int>(problem.frames.size());
  std::vector<double> windows;
  for (double fraction : options.window_fractions) {
    if (fraction > 0 && fraction < 1) windows.push_back(fraction);
  }
  if (options.window_fractions.empty() && map && fit_modulus) windows = {0.2, 0.5};

  const auto evaluator = make_evaluator(problem, layout);
  std::vector<double> start_residuals;
  // The start: with sensitivities its Jacobian comes with it (the fit's first, or the polish's);
  // with finite differences and no windows, the first Jacobian's points start on idle threads.
  if (!evaluator->start(result.start_values, start_residuals, windows.empty())) {
    throw std::runtime_error(label + "the simulation fails at the starting values");
  }
  result.start_residual_rms_m = rms(start_residuals, options.position_noise_m);

  // Does the start already explain the data within the noise?
  const int dof = std::max(1, layout.residual_count - static_cast<int>(parameters.size()));
  double chi_square = 0;
  for (double r : start_residuals) chi_square += r * r;
  result.start_chi_square_per_dof = chi_square / dof;
  result.explained_threshold = 1.0 + 3.0 * std::sqrt(2.0 / dof);
  const bool warm_started =
      options.warm_start && (result.warm_start.modulus_matched || result.warm_start.damping_matched);
  result.stopped_at_start =
      options.stop_when_explained && warm_started && result.start_chi_square_per_dof <= result.explained_threshold;

  FitOptions fit_options = options.fit;
  if (result.stopped_at_start) {
    // One polishing step from the warm start, no more; no windows.
    windows.clear();
    fit_options.max_iterations = 1;
    fit_options.projected_line_search = false;
    char line[256];
    std::snprintf(line, sizeof line,
                  "the warm start explains the data within the noise (chi-square per degree of freedom %.3g <= "
                  "%.3g at position_noise_m %.3g m): one polishing step, no iterations",
                  result.start_chi_square_per_dof, result.explained_threshold, options.position_noise_m);
    result.stop_reason = line;
  } else if (options.stop_when_explained && warm_started) {
    char line[256];
    std::snprintf(line, sizeof line,
                  "the warm start does not explain the data (chi-square per degree of freedom %.3g > %.3g): fitted",
                  result.start_chi_square_per_dof, result.explained_threshold);
    result.stop_reason = line;
  }

  for (double fraction : windows) {
    FemRecordingProblem window = problem;
    window.frames.resize(uz(std::max(3, static_cast<int>(std::ceil(fraction * frame_count)))));
    const Layout window_layout = make_layout(window);
    const auto window_evaluator = make_evaluator(window, window_layout);
    const FitResult partial = window_evaluator->fit(parameters, window_layout.residual_count, options.fit);
    for (std::size_t j = 0; j < parameters.size(); ++j) {
      parameters[j].initial = inside(partial.values[j], parameters[j].lower, parameters[j].upper);
    }
    result.window_iterations += partial.iterations;
    result.window_evaluations += partial.evaluations;
    result.simulations += window_evaluator->simulations();
  }

  result.fit = evaluator->fit(parameters, layout.residual_count, fit_options);
  std::vector<double> final_residuals;
  evaluator->evaluate(result.fit.values, final_residuals, false);
  result.residual_rms_m = rms(final_residuals, options.position_noise_m);
  if (result.stopped_at_start) {
    result.fit.converged = true;  // by the noise test, not by a tolerance
    result.fit.message = result.stop_reason + "; " + result.fit.message;
  }
  result.simulations += evaluator->simulations();

  result.names = result.fit.names;
  result.values = result.fit.values;
  result.standard_deviations = result.fit.standard_deviations;
  result.iterations = result.fit.iterations;
  result.evaluations = result.fit.evaluations;
  result.converged = result.fit.converged;
  result.message = result.fit.message;

  result.element_youngs_modulus_pa = element_moduli(result.values);
  if (fit_modulus) {
    result.control_youngs_modulus_pa.assign(result.values.begin(), result.values.begin() + k);
    result.control_youngs_modulus_sd_pa.assign(result.standard_deviations.begin(),
                                               result.standard_deviations.begin() + k);
  } else {
    result.control_youngs_modulus_pa.assign(uz(k), problem.material.youngs_modulus_pa);
    result.control_youngs_modulus_sd_pa.assign(uz(k), 0.0);
  }
  const auto [alpha, beta] = damping(result.values);
  result.rayleigh_alpha = alpha;
  result.rayleigh_beta = beta;
  result.rayleigh_alpha_sd = alpha_index >= 0 ? result.standard_deviations[uz(alpha_index)] : 0.0;
  result.rayleigh_beta_sd = beta_index >= 0 ? result.standard_deviations[uz(beta_index)] : 0.0;
  result.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  result.cpu_time_s = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  return result;
}

}  // namespace pliant::host::fem
