#include "pliant/host/diagnose/fem_model_run.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "pliant/host/diagnose/support_friction.hpp"
#include "pliant/host/fem/fem_condensation.hpp"
#include "pliant/host/fem/fem_modal.hpp"
#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/fem/fem_recording.hpp"
#include "pliant/host/fem/fem_solver.hpp"

namespace pliant::host {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;
// Rounds of (solve the full model, find the slips on the condensed one) per frame with sliding
// supports; the slips usually settle in 2-4.
constexpr int kMaxSlipRounds = 25;
// Cap of k eps^2 in exp(k eps^2): moduli stay within 1.6e5 times E, so the stiffness matrix stays
// well conditioned in badly distorted elements.
constexpr double kMaxStiffeningExponent = 12.0;

std::size_t at(int i) { return static_cast<std::size_t>(i); }

// Equivalent Biot strain sqrt(2/3) |dev(S - I)| per element, F = R S.
void element_strains(const fem::FemModel& model, const Eigen::VectorXd& x, Eigen::VectorXd& strain) {
  strain.resize(model.element_count());
  for (int e = 0; e < model.element_count(); ++e) {
    const Eigen::Matrix3d f = fem::deformation_gradient(model, e, x);
    const Eigen::Matrix3d r = fem::polar_rotation(f);
    const Eigen::Matrix3d s = r.transpose() * f;
    Eigen::Matrix3d biot = 0.5 * (s + s.transpose()) - Eigen::Matrix3d::Identity();
    biot -= (biot.trace() / 3.0) * Eigen::Matrix3d::Identity();
    const double value = std::sqrt(2.0 / 3.0) * biot.norm();
    strain(e) = std::isfinite(value) ? value : 0.0;
  }
}

// Linear interpolation of a time series (t ascending) at time `t`, held at the ends.
Eigen::Vector3d interpolate(const std::vector<double>& times, const std::vector<Eigen::Vector3d>& values, double t) {
  if (times.empty()) return Eigen::Vector3d::Constant(kNaN);
  if (t <= times.front()) return values.front();
  if (t >= times.back()) return values.back();
  const auto upper = std::upper_bound(times.begin(), times.end(), t);
  const std::size_t hi = static_cast<std::size_t>(upper - times.begin());
  const std::size_t lo = hi - 1;
  const double span = times[hi] - times[lo];
  const double s = span > 0 ? (t - times[lo]) / span : 1.0;
  return (1.0 - s) * values[lo] + s * values[hi];
}

}  // namespace

struct FemRecordingSimulator::Impl {
  fem::FemRecordingProblem problem;
  std::unique_ptr<fem::FemModel> model;
  Eigen::VectorXd rest0;
  Eigen::VectorXd base_youngs;  // scratch
  FemTimeMode mode = FemTimeMode::quasi_static;
  int n = 0;
  int frames = 0;
  std::vector<unsigned char> solved;
  std::vector<unsigned char> fitting;   // solved frames a fitting-only run solves
  std::vector<unsigned char> measured;  // wrench is a measurement in this frame
  std::vector<unsigned char> loaded;    // wrench is a load in this frame
  std::vector<double> measured_force;   // frames * 3
  std::vector<WrenchSample> samples;    // raw wrench stream (latency of loads)
  std::vector<unsigned char> is_fixed;  // per node
  std::vector<std::vector<int>> node_elements;
  double declared_youngs = 0;
  double tolerance = 1e-12;  // static convergence: largest node step (m)
  double declared_alpha = 0;
  double declared_beta = 0;
  Eigen::Vector3d declared_gravity = Eigen::Vector3d::Zero();
  std::map<std::vector<int>, std::unique_ptr<fem::FemSolver>> solvers;
  // Sliding supports (support_friction >= 0): the fixed nodes held as driven nodes at trial
  // positions, one solver per set of other driven nodes; their stiffness condensed onto them,
  // per driven set and step (static at E = 1 Pa, scaled; dynamic at the run's E).
  SupportPlane support_plane;
  std::map<std::vector<int>, std::unique_ptr<fem::FemSolver>> sliding_solvers;
  std::map<std::vector<int>, Eigen::MatrixXd> unit_support_stiffness;
  std::map<std::pair<std::vector<int>, double>, Eigen::MatrixXd> step_support_stiffness;
  double step_stiffness_modulus = 0;  // E of step_support_stiffness
  // The last elastic run, reused when only the force post-processing changes (a run of all
  // solved frames also serves a fitting-only request).
  bool cache_valid = false;
  bool cache_fitting_only = false;
  FemRunSettings cache_settings;
  ElasticRun cache;

  ElasticRun elastic_run(const FemRunSettings& settings, const std::vector<unsigned char>& solve);

  std::vector<int> driven_of(int f) const {
    std::vector<int> driven;
    for (int id : problem.frames[at(f)].driven_nodes) {
      if (is_fixed[at(id)] == 0) driven.push_back(id);
    }
    return driven;
  }

  Eigen::VectorXd driven_positions(int f, const std::vector<int>& driven) const {
    const fem::FemFrame& frame = problem.frames[at(f)];
    Eigen::VectorXd out(3 * static_cast<Eigen::Index>(driven.size()));
    std::size_t k = 0;
    for (std::size_t j = 0; j < frame.driven_nodes.size(); ++j) {
      if (is_fixed[at(frame.driven_nodes[j])] != 0) continue;
      out.segment<3>(3 * static_cast<Eigen::Index>(k)) =
          frame.driven_position_m.segment<3>(3 * static_cast<Eigen::Index>(j));
      ++k;
    }
    return out;
  }

  fem::FemSolver& solver_for(const std::vector<int>& driven) {
    auto found = solvers.find(driven);
    if (found != solvers.end()) return *found->second;
    auto solver = std::make_unique<fem::FemSolver>(*model, problem.fixed_nodes, driven);
    fem::FemSolver& ref = *solver;
    solvers.emplace(driven, std::move(solver));
    return ref;
  }

  // The wrench load of frame f (3n; empty when the frame has none), the stream read at t + lag.
  Eigen::VectorXd load_of(int f, double lag_s, const Eigen::VectorXd& position) const {
    if (loaded[at(f)] == 0) return Eigen::VectorXd();
    const double t = problem.frames[at(f)].time_s + lag_s;
    Eigen::Vector3d force = problem.frames[at(f)].wrench_force_n;
    Eigen::Vector3d torque = problem.frames[at(f)].wrench_torque_nm;
    if (lag_s != 0.0 && !samples.empty()) {
      const double tc = std::clamp(t, samples.front().t_s, samples.back().t_s);
      const auto upper = std::lower_bound(samples.begin(), samples.end(), tc,
                                          [](const WrenchSample& s, double time) { return s.t_s < time; });
      const WrenchSample& hi = upper == samples.end() ? samples.back() : *upper;
      const WrenchSample& lo = upper == samples.begin() || upper == samples.end() ? hi : *(upper - 1);
      const double span = hi.t_s - lo.t_s;
      const double s = span > 0 ? (tc - lo.t_s) / span : 1.0;
      for (int a = 0; a < 3; ++a) {
        force(a) = (1.0 - s) * lo.force_n[a] + s * hi.force_n[a];
        torque(a) = (1.0 - s) * lo.torque_nm[a] + s * hi.torque_nm[a];
      }
    }
    Eigen::VectorXd load = Eigen::VectorXd::Zero(3 * n);
    if (torque.norm() > 0 && problem.applied_to.size() >= 2) {
      fem::add_spread_wrench(force, torque, problem.applied_to, position, load);
    } else {
      fem::add_spread_force(force, problem.applied_to, n, load);
    }
    return load;
  }

  void set_moduli(const Eigen::VectorXd& base, double k, const Eigen::VectorXd& used_strain) {
    if (k == 0.0) {
      model->set_youngs_modulus(base);
      return;
    }
    Eigen::VectorXd moduli(base.size());
    for (Eigen::Index e = 0; e < base.size(); ++e) {
      moduli(e) = base(e) * std::exp(std::min(k * used_strain(e) * used_strain(e), kMaxStiffeningExponent));
    }
    model->set_youngs_modulus(moduli);
  }

  // Static equilibrium of frame f, with moduli consistent with the strains when stiffening.
  // The fixed point x = G(x), G one Newton step of FemSolver::solve_static with the moduli set
  // from the strains at x, is accelerated by Anderson mixing (depth 5): the corotational
  // tangent lacks the geometric stiffness, so plain Newton converges only linearly under
  // large compressive stress, and the moduli update adds a second linear iteration. Converged
  // when a step moves no node by more than `tolerance`. `x` is the start and receives the
  // solution; `reaction` the constraint forces there.
  void solve_static_frame(int f, const FemRunSettings& settings, const Eigen::VectorXd& base, Eigen::VectorXd& x,
                          Eigen::VectorXd& reaction) {
    const std::vector<int> driven = driven_of(f);
    equilibrium(f, solver_for(driven), driven_positions(f, driven), settings, base, x, reaction);
  }

  // The static equilibrium of frame f with `solver`'s driven nodes at `target`.
  void equilibrium(int f, fem::FemSolver& solver, const Eigen::VectorXd& target, const FemRunSettings& settings,
                   const Eigen::VectorXd& base, Eigen::VectorXd& x, Eigen::VectorXd& reaction) {
    const Eigen::VectorXd load = load_of(f, settings.wrench_latency_s, x);
    const double k = settings.stiffening;
    if (k == 0.0) model->set_youngs_modulus(base);
    fem::FemStaticOptions one_step;
    one_step.max_iterations = 1;
    one_step.displacement_tolerance_m = tolerance;
    constexpr std::size_t kDepth = 5;
    std::vector<Eigen::VectorXd> images;
    std::vector<Eigen::VectorXd> steps;
    double smallest = std::numeric_limits<double>::infinity();
    Eigen::VectorXd strain;
    for (int iteration = 0; iteration < 150; ++iteration) {
      if (k != 0.0) {
        element_strains(*model, x, strain);
        set_moduli(base, k, strain);
      }
      const fem::FemStaticResult result = solver.solve_static(target, load, one_step, x);
      if (!result.position_m.allFinite()) break;
      const Eigen::VectorXd& image = result.position_m;
      Eigen::VectorXd step = image - x;
      const double size = step.cwiseAbs().maxCoeff();
      if (size <= tolerance) {
        x = image;
        reaction = solver.reaction_n();
        return;
      }
      if (size > 1e3 * smallest) {  // the mixing went astray: restart from the plain step
        images.clear();
        steps.clear();
      }
      smallest = std::min(smallest, size);
      images.push_back(image);
      steps.push_back(std::move(step));
      if (images.size() > kDepth + 1) {
        images.erase(images.begin());
        steps.erase(steps.begin());
      }
      if (images.size() < 2) {
        x = images.back();
        continue;
      }
      const Eigen::Index columns = static_cast<Eigen::Index>(images.size()) - 1;
      Eigen::MatrixXd step_differences(x.size(), columns);
      Eigen::MatrixXd image_differences(x.size(), columns);
      for (Eigen::Index j = 0; j < columns; ++j) {
        step_differences.col(j) = steps[static_cast<std::size_t>(j) + 1] - steps[static_cast<std::size_t>(j)];
        image_differences.col(j) = images[static_cast<std::size_t>(j) + 1] - images[static_cast<std::size_t>(j)];
      }
      const Eigen::VectorXd gamma = step_differences.colPivHouseholderQr().solve(steps.back());
      Eigen::VectorXd mixed = images.back() - image_differences * gamma;
      x = mixed.allFinite() ? mixed : images.back();
    }
    throw std::runtime_error("static solve did not converge in frame " + std::to_string(f));
  }

  // --- sliding supports ---------------------------------------------------------------------

  bool sliding(const FemRunSettings& settings) const { return settings.support_friction >= 0 && support_plane.valid; }

  fem::FemSolver& sliding_solver_for(const std::vector<int>& driven) {
    auto found = sliding_solvers.find(driven);
    if (found != sliding_solvers.end()) return *found->second;
    std::vector<int> held = problem.fixed_nodes;
    held.insert(held.end(), driven.begin(), driven.end());
    auto solver = std::make_unique<fem::FemSolver>(*model, std::vector<int>{}, held);
    fem::FemSolver& ref = *solver;
    sliding_solvers.emplace(driven, std::move(solver));
    return ref;
  }

  // The supports' stiffness with the driven nodes held: static (dt 0) at `modulus`, or that of
  // one Newmark step of length dt (mass and Rayleigh terms included).
  Eigen::MatrixXd support_stiffness(const std::vector<int>& driven, double dt, double modulus) {
    if (dt <= 0) {
      auto found = unit_support_stiffness.find(driven);
      if (found == unit_support_stiffness.end()) {
        fem::FemModel unit = *model;
        unit.set_rest_position(rest0);
        unit.set_youngs_modulus(1.0);
        found =
            unit_support_stiffness.emplace(driven, fem::condensed_stiffness(unit, rest0, problem.fixed_nodes, driven))
                .first;
      }
      return modulus * found->second;
    }
    if (modulus != step_stiffness_modulus) {
      step_support_stiffness.clear();
      step_stiffness_modulus = modulus;
    }
    // Steps of jittered frame clocks share a matrix: dt is taken in buckets of 2 %. The matrix
    // only steers the contact iteration; the full model checks every answer.
    const double bucket_dt = std::exp(std::round(50.0 * std::log(dt)) / 50.0);
    const auto key = std::make_pair(driven, bucket_dt);
    auto found = step_support_stiffness.find(key);
    if (found == step_support_stiffness.end()) {
      dt = bucket_dt;
      fem::FemModel scaled = *model;
      scaled.set_rest_position(rest0);
      scaled.set_youngs_modulus(modulus);
      const double alpha = model->rayleigh_alpha();
      const double beta = model->rayleigh_beta();
      found = step_support_stiffness
                  .emplace(key, fem::condensed_stiffness(scaled, rest0, problem.fixed_nodes, driven,
                                                         1.0 + 2.0 * beta / dt, 4.0 / (dt * dt) + 2.0 * alpha / dt))
                  .first;
    }
    return found->second;
  }

  // The entries of a 3n per-node vector at the supports (3 per fixed node, in their order).
  Eigen::VectorXd at_supports(const Eigen::VectorXd& per_node) const {
    Eigen::VectorXd out(3 * static_cast<Eigen::Index>(problem.fixed_nodes.size()));
    for (std::size_t i = 0; i < problem.fixed_nodes.size(); ++i) {
      out.segment<3>(3 * static_cast<Eigen::Index>(i)) = per_node.segment<3>(3 * problem.fixed_nodes[i]);
    }
    return out;
  }

  // Rounds of: hold the supports at anchors + slip and solve (`solve_held`, which returns the
  // reactions), then find the slips that satisfy Coulomb's law on the condensed stiffness. The
  // anchors advance by the frame's slip.
  template <typename SolveHeld>
  void slide(double mu, const Eigen::MatrixXd& stiffness, Eigen::VectorXd& anchors, SolveHeld&& solve_held) {
    const double slip_tolerance = 100.0 * tolerance;  // 1e-6 of the object's size
    Eigen::VectorXd slip = Eigen::VectorXd::Zero(anchors.size());
    for (int round = 0; round < kMaxSlipRounds; ++round) {
      const Eigen::VectorXd held = at_supports(solve_held(Eigen::VectorXd(anchors + slip)));
      const Eigen::VectorXd next = coulomb_slip(support_plane, mu, held, stiffness, slip, 1e-2 * slip_tolerance);
      const double change = (next - slip).cwiseAbs().maxCoeff();
      slip = next;
      if (change <= slip_tolerance) break;
    }
    anchors += slip;
  }

  void solve_static_frame_sliding(int f, const FemRunSettings& settings, const Eigen::VectorXd& base,
                                  Eigen::VectorXd& x, Eigen::VectorXd& reaction, Eigen::VectorXd& anchors) {
    const std::vector<int> driven = driven_of(f);
    fem::FemSolver& solver = sliding_solver_for(driven);
    const Eigen::Index supports = anchors.size();
    Eigen::VectorXd target(supports + 3 * static_cast<Eigen::Index>(driven.size()));
    target.tail(target.size() - supports) = driven_positions(f, driven);
    slide(settings.support_friction, support_stiffness(driven, 0.0, settings.youngs_modulus_pa), anchors,
          [&](const Eigen::VectorXd& support_positions) {
            target.head(supports) = support_positions;
            equilibrium(f, solver, target, settings, base, x, reaction);
            return reaction;
          });
  }

  void step_sliding(int f, double dt, const FemRunSettings& settings, const Eigen::VectorXd& load,
                    const fem::FemStepOptions& options, fem::FemState& state, Eigen::VectorXd& anchors) {
    const std::vector<int> driven = driven_of(f);
    fem::FemSolver& solver = sliding_solver_for(driven);
    const Eigen::Index supports = anchors.size();
    Eigen::VectorXd target(supports + 3 * static_cast<Eigen::Index>(driven.size()));
    target.tail(target.size() - supports) = driven_positions(f, driven);
    const fem::FemState start = state;
    slide(settings.support_friction, support_stiffness(driven, dt, settings.youngs_modulus_pa), anchors,
          [&](const Eigen::VectorXd& support_positions) {
            target.head(supports) = support_positions;
            state = start;
            solver.step(state, dt, target, load, options);
            return solver.reaction_n();
          });
  }

  // Plastic creep of the rest shape toward the current shape after a solved frame.
  void creep(const FemRunSettings& settings, const Eigen::VectorXd& x, double dt) {
    if (settings.plastic_creep <= 0.0 || dt <= 0.0) return;
    Eigen::VectorXd strain;
    element_strains(*model, x, strain);
    const Eigen::VectorXd& rest = model->rest_position_m();
    // Rigid motion rest -> current (Kabsch), removed from the current shape.
    Eigen::Vector3d rest_centre = Eigen::Vector3d::Zero();
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i) {
      rest_centre += rest.segment<3>(3 * i);
      centre += x.segment<3>(3 * i);
    }
    rest_centre /= n;
    centre /= n;
    Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();
    for (int i = 0; i < n; ++i)
      cross += (x.segment<3>(3 * i) - centre) * (rest.segment<3>(3 * i) - rest_centre).transpose();
    const Eigen::Matrix3d rotation = fem::polar_rotation(cross);
    const double alpha = std::min(1.0, settings.plastic_creep * dt);
    Eigen::VectorXd next = rest;
    bool changed = false;
    for (int i = 0; i < n; ++i) {
      if (is_fixed[at(i)] != 0) continue;
      double largest = 0;
      for (int e : node_elements[at(i)]) largest = std::max(largest, strain(e));
      if (largest <= settings.plastic_yield) continue;
      const Eigen::Vector3d unrotated = rotation.transpose() * (x.segment<3>(3 * i) - centre) + rest_centre;
      next.segment<3>(3 * i) += alpha * (unrotated - rest.segment<3>(3 * i));
      changed = true;
    }
    if (changed) model->set_rest_position(next);
  }
};

FemRecordingSimulator::FemRecordingSimulator(const Recording& recording, FemTimeMode mode, int frame_stride)
    : impl_(std::make_unique<Impl>()) {
  Impl& im = *impl_;
  im.problem = fem::fem_problem_from_recording(recording);
  im.mode = mode;
  im.n = im.problem.mesh.point_count();
  im.frames = static_cast<int>(im.problem.frames.size());
  for (const auto& [key, value] : recording.material) {
    if (key == "youngs_modulus") im.declared_youngs = value;
  }
  im.declared_alpha = im.problem.material.rayleigh_alpha;
  im.declared_beta = im.problem.material.rayleigh_beta;
  im.declared_gravity = im.problem.material.gravity_m_s2;
  fem::FemMaterial material = im.problem.material;
  if (!(material.youngs_modulus_pa > 0)) material.youngs_modulus_pa = 1e5;
  TetMesh mesh = im.problem.mesh;
  mesh.youngs_modulus.clear();  // diagnose fits one homogeneous modulus
  im.model = std::make_unique<fem::FemModel>(mesh, material);
  im.rest0 = im.model->rest_position_m();
  {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (int i = 0; i < im.n; ++i) {
      lo = lo.cwiseMin(im.rest0.segment<3>(3 * i));
      hi = hi.cwiseMax(im.rest0.segment<3>(3 * i));
    }
    im.tolerance = 1e-8 * std::max((hi - lo).norm(), 1e-9);
  }
  im.samples = recording.wrench;

  im.is_fixed.assign(at(im.n), 0);
  for (int id : im.problem.fixed_nodes) im.is_fixed[at(id)] = 1;
  {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int i = 0; i < im.n; ++i) centre += im.rest0.segment<3>(3 * i);
    im.support_plane = find_support_plane(im.rest0, im.problem.fixed_nodes, centre / std::max(1, im.n));
  }
  im.node_elements.assign(at(im.n), {});
  for (int e = 0; e < im.model->element_count(); ++e) {
    for (int node : im.model->elements()[at(e)]) im.node_elements[at(node)].push_back(e);
  }

  bool constrained = !im.problem.fixed_nodes.empty();
  im.measured.assign(at(im.frames), 0);
  im.loaded.assign(at(im.frames), 0);
  im.measured_force.assign(at(im.frames) * 3, kNaN);
  for (int f = 0; f < im.frames; ++f) {
    const fem::FemFrame& frame = im.problem.frames[at(f)];
    if (!frame.driven_nodes.empty()) constrained = true;
    if (!frame.has_wrench) continue;
    for (int a = 0; a < 3; ++a) im.measured_force[at(f) * 3 + at(a)] = frame.wrench_force_n(a);
    bool all = true;
    for (int id : im.problem.applied_to) {
      const bool driven = std::binary_search(frame.driven_nodes.begin(), frame.driven_nodes.end(), id);
      if (!driven && im.is_fixed[at(id)] == 0) all = false;
    }
    (all ? im.measured : im.loaded)[at(f)] = 1;
  }
  if (!constrained) {
    throw std::invalid_argument("recording " + recording.name +
                                ": no fixed or driven particle holds the body; the FEM needs a support or a driver");
  }
  const int stride = mode == FemTimeMode::dynamic ? 1 : std::max(1, frame_stride);
  im.solved.assign(at(im.frames), 0);
  for (int f = 0; f < im.frames; f += stride) im.solved[at(f)] = 1;
  if (im.frames > 0) im.solved[at(im.frames - 1)] = 1;
  im.fitting = im.solved;
}

void FemRecordingSimulator::set_fitting_frames(const std::vector<unsigned char>& frames) {
  Impl& im = *impl_;
  if (frames.size() != im.solved.size()) throw std::invalid_argument("set_fitting_frames: one entry per frame");
  bool first = true;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    im.fitting[f] = im.solved[f] != 0 && (frames[f] != 0 || first) ? 1 : 0;
    if (im.solved[f] != 0) first = false;
  }
  if (im.cache_fitting_only) im.cache_valid = false;
}

FemRecordingSimulator::~FemRecordingSimulator() = default;

FemTimeMode FemRecordingSimulator::mode() const { return impl_->mode; }
const std::vector<unsigned char>& FemRecordingSimulator::solved() const { return impl_->solved; }
const std::vector<unsigned char>& FemRecordingSimulator::force_measured() const { return impl_->measured; }
const std::vector<double>& FemRecordingSimulator::measured_force() const { return impl_->measured_force; }
bool FemRecordingSimulator::has_load() const {
  return std::find(impl_->loaded.begin(), impl_->loaded.end(), 1) != impl_->loaded.end();
}
double FemRecordingSimulator::poisson_ratio() const { return impl_->problem.material.poisson_ratio; }
double FemRecordingSimulator::density_kg_m3() const { return impl_->problem.material.density_kg_m3; }
double FemRecordingSimulator::declared_youngs_modulus_pa() const { return impl_->declared_youngs; }
bool FemRecordingSimulator::gravity_declared() const { return impl_->problem.gravity_declared; }
int FemRecordingSimulator::element_count() const { return impl_->model->element_count(); }

bool FemRecordingSimulator::scale_invariant(const FemRunSettings& settings) const {
  return impl_->mode == FemTimeMode::quasi_static && !has_load() &&
         (impl_->declared_gravity + settings.extra_gravity_m_s2).squaredNorm() == 0.0;
}

bool FemRecordingSimulator::scale_invariant_at_fixed_gravity_ratio() const {
  return impl_->mode == FemTimeMode::quasi_static && !has_load();
}

Eigen::Vector3d FemRecordingSimulator::declared_gravity_m_s2() const { return impl_->declared_gravity; }
bool FemRecordingSimulator::has_support_plane() const { return impl_->support_plane.valid; }
Eigen::Vector3d FemRecordingSimulator::support_normal() const { return impl_->support_plane.normal; }

std::vector<double> FemRecordingSimulator::element_centroids() const {
  const fem::FemModel& model = *impl_->model;
  std::vector<double> out;
  out.reserve(at(model.element_count()) * 3);
  for (int e = 0; e < model.element_count(); ++e) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int node : model.elements()[at(e)]) c += impl_->rest0.segment<3>(3 * node);
    c /= 4.0;
    out.insert(out.end(), {c(0), c(1), c(2)});
  }
  return out;
}

double FemRecordingSimulator::lowest_period_s(double youngs_modulus_pa) const {
  const Impl& im = *impl_;
  try {
    fem::FemModel model = *im.model;
    model.set_rest_position(im.rest0);
    model.set_youngs_modulus(youngs_modulus_pa);
    std::vector<int> clamped = im.problem.fixed_nodes;
    if (im.frames > 0) {
      for (int id : im.driven_of(0)) clamped.push_back(id);
    }
    if (3 * (im.n - static_cast<int>(clamped.size())) < 3) return std::numeric_limits<double>::infinity();
    fem::FemModalOptions options;
    options.mode_count = 1;
    const fem::FemModes modes = fem::modal_analysis(model, clamped, options);
    const double omega = modes.omega_rad_s.size() > 0 ? modes.omega_rad_s(0) : 0.0;
    return omega > 0 ? 2.0 * kPi / omega : std::numeric_limits<double>::infinity();
  } catch (const std::exception&) {
    return std::numeric_limits<double>::infinity();
  }
}

double FemRecordingSimulator::loading_time_s() const {
  const Impl& im = *impl_;
  double best = std::numeric_limits<double>::infinity();
  // Driven nodes: travel from rest over the largest speed between consecutive frames.
  std::map<int, Eigen::Vector3d> last;
  std::map<int, double> last_time;
  double travel = 0;
  double speed = 0;
  for (int f = 0; f < im.frames; ++f) {
    const fem::FemFrame& frame = im.problem.frames[at(f)];
    for (std::size_t j = 0; j < frame.driven_nodes.size(); ++j) {
      const int id = frame.driven_nodes[j];
      const Eigen::Vector3d p = frame.driven_position_m.segment<3>(3 * static_cast<Eigen::Index>(j));
      travel = std::max(travel, (p - im.rest0.segment<3>(3 * id)).norm());
      const auto found = last.find(id);
      if (found != last.end() && frame.time_s > last_time[id]) {
        speed = std::max(speed, (p - found->second).norm() / (frame.time_s - last_time[id]));
      }
      last[id] = p;
      last_time[id] = frame.time_s;
    }
  }
  if (travel > 0 && speed > 0) best = std::min(best, travel / speed);
  // Loads: largest force over its largest rate.
  double force = 0;
  double rate = 0;
  for (int f = 0; f < im.frames; ++f) {
    if (im.loaded[at(f)] == 0) continue;
    const Eigen::Vector3d value = im.problem.frames[at(f)].wrench_force_n;
    force = std::max(force, value.norm());
    if (f > 0 && im.loaded[at(f - 1)] != 0) {
      const double dt = im.problem.frames[at(f)].time_s - im.problem.frames[at(f - 1)].time_s;
      if (dt > 0) rate = std::max(rate, (value - im.problem.frames[at(f - 1)].wrench_force_n).norm() / dt);
    }
  }
  if (force > 0 && rate > 0) best = std::min(best, force / rate);
  return best;
}

namespace {

// Whether two settings give the same elastic run (they may differ in the force post-processing:
// relaxation, and latency when no frame takes the wrench as a load).
bool same_physics(const FemRunSettings& a, const FemRunSettings& b, bool latency_matters) {
  return a.youngs_modulus_pa == b.youngs_modulus_pa && a.extra_gravity_m_s2 == b.extra_gravity_m_s2 &&
         a.stiffening == b.stiffening && a.extra_rayleigh_beta == b.extra_rayleigh_beta &&
         a.plastic_yield == b.plastic_yield && a.plastic_creep == b.plastic_creep &&
         (!latency_matters || a.wrench_latency_s == b.wrench_latency_s) && a.element_factor == b.element_factor &&
         a.support_friction == b.support_friction;
}

}  // namespace

FemRun FemRecordingSimulator::simulate(const FemRunSettings& settings, bool fitting_only) {
  Impl& im = *impl_;
  const bool latency_matters = has_load();
  const bool restricted = fitting_only && im.mode == FemTimeMode::quasi_static && im.fitting != im.solved;
  if (!im.cache_valid || !same_physics(im.cache_settings, settings, latency_matters) ||
      (im.cache_fitting_only && !restricted)) {
    im.cache_valid = false;
    im.cache = im.elastic_run(settings, restricted ? im.fitting : im.solved);
    im.cache_settings = settings;
    im.cache_fitting_only = restricted;
    im.cache_valid = true;
  }
  const ElasticRun& elastic_run = im.cache;
  FemRun run;
  run.ok = elastic_run.ok;
  run.failure = elastic_run.failure;
  run.positions = elastic_run.positions;
  run.force.assign(at(im.frames) * 3, kNaN);
  if (!run.ok) return run;
  const std::vector<double>& force_times = elastic_run.force_times;
  const std::vector<Eigen::Vector3d>& elastic = elastic_run.elastic;
  // Relaxation (quasi-linear viscoelasticity) of the force, then the stream's latency.
  std::vector<Eigen::Vector3d> total = elastic;
  if (settings.relaxation_fraction != 0.0 && settings.relaxation_time_s > 0) {
    Eigen::Vector3d q = Eigen::Vector3d::Zero();
    for (std::size_t j = 1; j < elastic.size(); ++j) {
      const double dt = force_times[j] - force_times[j - 1];
      const double a = std::exp(-dt / settings.relaxation_time_s);
      const double gain = dt > 0 ? settings.relaxation_time_s / dt * (1.0 - a) : 1.0;
      q = a * q + settings.relaxation_fraction * gain * (elastic[j] - elastic[j - 1]);
      total[j] = elastic[j] + q;
    }
  }
  for (std::size_t j = 0; j < elastic_run.force_frames.size(); ++j) {
    const Eigen::Vector3d value = settings.wrench_latency_s == 0.0
                                      ? total[j]
                                      : interpolate(force_times, total, force_times[j] - settings.wrench_latency_s);
    for (int a = 0; a < 3; ++a) run.force[at(elastic_run.force_frames[j]) * 3 + at(a)] = value(a);
  }
  return run;
}

FemRecordingSimulator::ElasticRun FemRecordingSimulator::Impl::elastic_run(const FemRunSettings& settings,
                                                                           const std::vector<unsigned char>& solve) {
  Impl& im = *this;
  ElasticRun run;
  run.positions.assign(at(im.frames) * at(im.n) * 3, kNaN);
  const int m = im.model->element_count();
  try {
    if (!(settings.youngs_modulus_pa > 0) || !std::isfinite(settings.youngs_modulus_pa)) {
      throw std::runtime_error("Young's modulus must be positive");
    }
    im.model->set_rest_position(im.rest0);
    im.model->set_gravity(im.declared_gravity + settings.extra_gravity_m_s2);
    im.model->set_rayleigh(im.declared_alpha, im.declared_beta + std::max(0.0, settings.extra_rayleigh_beta));
    Eigen::VectorXd base = Eigen::VectorXd::Constant(m, settings.youngs_modulus_pa);
    if (static_cast<int>(settings.element_factor.size()) == m) {
      for (int e = 0; e < m; ++e) base(e) *= settings.element_factor[at(e)];
    }
    Eigen::VectorXd strain;
    Eigen::VectorXd x = im.rest0;
    Eigen::VectorXd reaction;
    const bool sliding = im.sliding(settings);
    Eigen::VectorXd anchors;  // where the sliding supports stick (3 per fixed node)
    if (sliding) anchors = im.at_supports(im.rest0);
    auto record = [&](int f, const Eigen::VectorXd& position, const Eigen::VectorXd& constraint_force) {
      std::copy(position.data(), position.data() + 3 * im.n,
                run.positions.begin() + static_cast<long>(at(f) * at(im.n) * 3));
      if (im.measured[at(f)] != 0) {
        run.force_frames.push_back(f);
        run.force_times.push_back(im.problem.frames[at(f)].time_s);
        run.elastic.push_back(fem::net_force(constraint_force, im.problem.applied_to));
      }
    };

    if (im.mode == FemTimeMode::quasi_static) {
      // Warm start: the last two solutions extrapolated linearly in time.
      Eigen::VectorXd last;
      Eigen::VectorXd before_last;
      double last_time = 0;
      double before_last_time = 0;
      double previous_time = im.frames > 0 ? im.problem.frames[0].time_s : 0.0;
      for (int f = 0; f < im.frames; ++f) {
        if (solve[at(f)] == 0) continue;
        const double t = im.problem.frames[at(f)].time_s;
        if (before_last.size() > 0 && last_time > before_last_time) {
          const double ratio = std::min(2.0, (t - last_time) / (last_time - before_last_time));
          x = last + ratio * (last - before_last);
        }
        if (sliding) {
          im.solve_static_frame_sliding(f, settings, base, x, reaction, anchors);
        } else {
          im.solve_static_frame(f, settings, base, x, reaction);
        }
        record(f, x, reaction);
        im.creep(settings, x, t - previous_time);
        previous_time = t;
        before_last = std::move(last);
        before_last_time = last_time;
        last = x;
        last_time = t;
      }
    } else {
      if (sliding) {
        im.solve_static_frame_sliding(0, settings, base, x, reaction, anchors);
      } else {
        im.solve_static_frame(0, settings, base, x, reaction);
      }
      record(0, x, reaction);
      fem::FemState state;
      state.position_m = x;
      state.velocity_m_s = Eigen::VectorXd::Zero(3 * im.n);
      state.acceleration_m_s2 = Eigen::VectorXd::Zero(3 * im.n);
      state.time_s = im.problem.frames[0].time_s;
      state.acceleration_valid = false;
      fem::FemStepOptions options;
      options.integrator = fem::FemIntegrator::newmark;
      for (int f = 1; f < im.frames; ++f) {
        const double dt = im.problem.frames[at(f)].time_s - im.problem.frames[at(f - 1)].time_s;
        if (settings.stiffening != 0.0) {
          element_strains(*im.model, state.position_m, strain);
          im.set_moduli(base, settings.stiffening, strain);
        } else {
          im.model->set_youngs_modulus(base);
        }
        const std::vector<int> driven = im.driven_of(f);
        const Eigen::VectorXd load = im.load_of(f, settings.wrench_latency_s, state.position_m);
        if (driven != im.driven_of(f - 1)) state.acceleration_valid = false;
        if (sliding) {
          im.step_sliding(f, dt, settings, load, options, state, anchors);
          reaction = im.sliding_solver_for(driven).reaction_n();
        } else {
          fem::FemSolver& solver = im.solver_for(driven);
          solver.step(state, dt, im.driven_positions(f, driven), load, options);
          reaction = solver.reaction_n();
        }
        if (!state.position_m.allFinite()) throw std::runtime_error("the dynamic run diverged");
        record(f, state.position_m, reaction);
        im.creep(settings, state.position_m, dt);
      }
    }
  } catch (const std::exception& error) {
    run.ok = false;
    run.failure = error.what();
  }
  return run;
}

}  // namespace pliant::host
