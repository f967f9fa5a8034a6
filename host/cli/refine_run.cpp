#include "refine_run.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "exit_status.hpp"
#include "pliant/host/fem/cylinder_mesh.hpp"
#include "pliant/host/fem/estimate_dynamic.hpp"
#include "pliant/host/fem/estimate_static.hpp"
#include "pliant/host/fem/material_map.hpp"
#include "pliant/host/fem/material_map_selection.hpp"

namespace pliant::cli {
namespace {

using namespace host::fem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::size_t uz(int i) { return static_cast<std::size_t>(i); }
Eigen::Index ix(int i) { return static_cast<Eigen::Index>(i); }

bool contains(const std::vector<int>& sorted, int value) {
  return std::binary_search(sorted.begin(), sorted.end(), value);
}

Eigen::VectorXd mesh_points(const host::TetMesh& mesh) {
  return Eigen::Map<const Eigen::VectorXd>(mesh.points.data(), static_cast<Eigen::Index>(mesh.points.size()));
}

// JSON number, or null for NaN and infinities (JSON has neither).
nlohmann::json number(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

std::function<void(int, int, double)> reporter(RefineProgress& progress) {
  return [&progress](int pass, int iteration, double cost) { progress.iteration(pass, iteration, cost); };
}

// ---------------------------------------------------------------------------------------------
// Static estimators

void fill_static(const YoungsModulusEstimate& e, RefineOutcome& out, int elements) {
  out.estimated["youngs_modulus"] = e.youngs_modulus_pa;
  out.uncertainty["youngs_modulus"] = e.standard_deviation_pa;
  out.element_youngs_modulus_pa = Eigen::VectorXd::Constant(ix(elements), e.youngs_modulus_pa);
  for (const StaticFrameRow& row : e.frames) out.simulated.push_back({row.frame, row.position_m});
  out.converged = e.converged;
  out.fit_message = e.message;
  nlohmann::json& d = out.diagnostics;
  d["converged"] = e.converged;
  d["frames_used"] = e.frames_used;
  d["residual_count"] = e.residual_count;
  d["iterations"] = e.iterations;
  d["evaluations"] = e.evaluations;
  d["static_solves"] = e.static_solves;
  d["start_youngs_modulus"] = e.initial_youngs_modulus_pa;
  d["position_noise"] = number(e.position_noise_m);
  d["message"] = e.message;
}

void run_force(const FemRecordingProblem& problem, const RefineSettings& s, RefineProgress& progress,
               RefineOutcome& out) {
  YoungsModulusOptions o;
  o.initial_youngs_modulus_pa = s.initial_youngs_modulus_pa;
  o.threads = s.threads;
  o.keep_frame_positions = true;
  o.fit.on_iteration = reporter(progress);
  progress.stage("force estimator, youngs_modulus");
  const YoungsModulusEstimate e = estimate_youngs_modulus_from_force(problem, o);
  fill_static(e, out, problem.mesh.tet_count());
}

void run_reaction(const FemRecordingProblem& problem, const RefineSettings& s, RefineProgress& progress,
                  RefineOutcome& out) {
  ReactionEstimateOptions o;
  if (s.max_strain < 1.0) o.max_nominal_strain = s.max_strain;
  o.fit_force_offset = s.force_offset;
  o.initial_youngs_modulus_pa = s.initial_youngs_modulus_pa;
  o.threads = s.threads;
  o.keep_frame_positions = true;
  o.fit.on_iteration = reporter(progress);
  progress.stage("reaction estimator, youngs_modulus");
  YoungsModulusEstimate e;
  try {
    e = estimate_youngs_modulus_from_reaction(problem, o);
  } catch (const std::invalid_argument& error) {
    const std::string what = error.what();
    if (what.find("max_nominal_strain") == std::string::npos) throw;
    throw UsageError(what + "; pass --max-strain 1 to use every frame");
  }
  fill_static(e, out, problem.mesh.tet_count());
  nlohmann::json& d = out.diagnostics;
  d["force_rms"] = number(e.force_rms_n);
  d["force_noise"] = number(e.force_noise_n);
  d["max_strain"] = s.max_strain < 1.0 ? nlohmann::json(s.max_strain) : nlohmann::json();
  double strain = 0;
  for (const StaticFrameRow& row : e.frames) strain = std::max(strain, row.nominal_strain);
  d["last_strain"] = number(strain);
  if (s.force_offset) d["force_offset"] = {e.force_offset_n.x(), e.force_offset_n.y(), e.force_offset_n.z()};
}

// ---------------------------------------------------------------------------------------------
// Trajectory estimator

// Volume-weighted geometric mean of the map's element moduli and its standard deviation from the
// covariance of the control values: log E_mean = sum_i a_i log v_i with a_i the volume share of
// control point i's weights.
std::pair<double, double> map_mean(const FemRecordingProblem& problem, const MaterialMap& map,
                                   const TrajectoryEstimate& fit, int k) {
  const Eigen::MatrixXd& w = map.weights();
  Eigen::VectorXd share = Eigen::VectorXd::Zero(ix(k));
  double total = 0;
  for (int e = 0; e < problem.mesh.tet_count(); ++e) {
    const double volume = std::abs(host::tet_signed_volume(problem.mesh, e));
    share += volume * w.row(ix(e)).transpose();
    total += volume;
  }
  share /= total;
  double log_mean = 0;
  for (int i = 0; i < k; ++i) log_mean += share(ix(i)) * std::log(fit.control_youngs_modulus_pa[uz(i)]);
  const double mean = std::exp(log_mean);
  if (fit.fit.covariance.rows() < k) return {mean, kNaN};
  double variance = 0;
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      variance += share(ix(i)) * share(ix(j)) * fit.fit.covariance(ix(i), ix(j)) /
                  (fit.control_youngs_modulus_pa[uz(i)] * fit.control_youngs_modulus_pa[uz(j)]);
    }
  }
  return {mean, variance >= 0 ? mean * std::sqrt(variance) : kNaN};
}

// What the control-point selection tried and chose (card diagnostics "material_map_selection"),
// and a warning per control point the data do not determine.
void report_selection(const MaterialMapSelection& selection, RefineOutcome& out) {
  nlohmann::json tried = nlohmann::json::array();
  for (const MaterialMapCandidate& c : selection.candidates) {
    tried.push_back({{"control_points", c.control_points},
                     {"parameters", c.parameters},
                     {"rms", number(c.residual_rms_m * std::sqrt(3.0))},
                     {"lag1_correlation", number(c.lag1_correlation)},
                     {"bic", number(c.bic)},
                     {"converged", c.converged}});
  }
  const MaterialMapCandidate& chosen = selection.candidates[static_cast<std::size_t>(selection.chosen)];
  out.diagnostics["material_map_selection"] = {{"tried", tried},
                                               {"chosen_control_points", chosen.control_points},
                                               {"design_effect", number(selection.design_effect)},
                                               {"undetermined", selection.undetermined}};
  for (int i : selection.undetermined) {
    const Eigen::Vector3d& p = selection.estimate.control_points_m[static_cast<std::size_t>(i)];
    out.warnings.push_back("material_map: control point " + std::to_string(i) + " at (" + std::to_string(p.x()) + ", " +
                           std::to_string(p.y()) + ", " + std::to_string(p.z()) +
                           ") m is not determined by the data (its modulus is unreliable)");
  }
}

void run_trajectory(const FemRecordingProblem& problem, const RefinePlan& plan, const RefineSettings& s,
                    RefineProgress& progress, RefineOutcome& out) {
  TrajectoryEstimateOptions o;
  o.estimate_youngs_modulus = plan.youngs_modulus;
  o.estimate_rayleigh_alpha = plan.rayleigh_alpha;
  o.estimate_rayleigh_beta = plan.rayleigh_beta;
  o.initial_youngs_modulus_pa = s.initial_youngs_modulus_pa;
  o.simulation.substeps = s.substeps;
  o.threads = s.threads;
  if (s.position_noise_m > 0) {
    o.position_noise_m = s.position_noise_m;
  } else {
    o.stop_when_explained = false;  // no noise to compare the start with
  }
  o.fit.on_iteration = reporter(progress);
  const bool select = plan.material_map && s.select_control_points;
  if (plan.material_map && !select) {
    o.control_points_m =
        s.control_points_m.empty() ? place_control_points(problem.mesh, s.control_point_count) : s.control_points_m;
  }
  MaterialMapSelection selection;
  if (select) {
    progress.stage("trajectory estimator: material maps of 1, 2, 4, ... control points");
    selection = select_material_map(problem, o);
    o.control_points_m = selection.estimate.control_points_m;
    report_selection(selection, out);
  } else {
    progress.stage("trajectory estimator, modal warm start and fit");
  }
  const TrajectoryEstimate e = select ? std::move(selection.estimate) : estimate_trajectory_parameters(problem, o);

  const int k = static_cast<int>(e.control_youngs_modulus_pa.size());
  if (plan.material_map) {
    const MaterialMap map(problem.mesh, o.control_points_m, o.material_map);
    out.has_map = true;
    out.control_points_m = e.control_points_m;
    out.control_youngs_modulus_pa = e.control_youngs_modulus_pa;
    out.control_youngs_modulus_sd_pa = e.control_youngs_modulus_sd_pa;
    out.kernel_width_m = map.kernel_width_m();
    const auto [mean, sd] = map_mean(problem, map, e, k);
    out.estimated["youngs_modulus"] = mean;
    out.uncertainty["youngs_modulus"] = sd;
  } else if (plan.youngs_modulus) {
    out.estimated["youngs_modulus"] = e.control_youngs_modulus_pa.at(0);
    out.uncertainty["youngs_modulus"] = e.control_youngs_modulus_sd_pa.at(0);
  }
  if (plan.rayleigh_alpha) {
    out.estimated["rayleigh_alpha"] = e.rayleigh_alpha;
    out.uncertainty["rayleigh_alpha"] = e.rayleigh_alpha_sd;
  }
  if (plan.rayleigh_beta) {
    out.estimated["rayleigh_beta"] = e.rayleigh_beta;
    out.uncertainty["rayleigh_beta"] = e.rayleigh_beta_sd;
  }
  for (const char* name : {"rayleigh_alpha", "rayleigh_beta"}) {
    if (out.estimated.count(name) == 0 && !problem.is_known(name)) {
      out.assumed[name] =
          std::string(name) == "rayleigh_alpha" ? problem.material.rayleigh_alpha : problem.material.rayleigh_beta;
    }
  }
  out.element_youngs_modulus_pa = e.element_youngs_modulus_pa;
  out.converged = e.converged;
  out.fit_message = "trajectory fit: " + e.message;

  progress.stage("simulating the fitted model");
  const std::vector<Eigen::VectorXd> positions =
      simulate_trajectory(problem, e.element_youngs_modulus_pa, e.rayleigh_alpha, e.rayleigh_beta, o.simulation);
  for (std::size_t f = 0; f < positions.size(); ++f) out.simulated.push_back({static_cast<int>(f), positions[f]});

  nlohmann::json& d = out.diagnostics;
  d["converged"] = e.converged;
  d["frames_used"] = static_cast<int>(problem.frames.size());
  d["residual_count"] = e.residual_count;
  d["iterations"] = e.iterations + e.window_iterations;
  d["evaluations"] = e.evaluations + e.window_evaluations;
  d["simulations"] = e.simulations;
  d["substeps"] = s.substeps;
  d["position_noise"] = number(o.position_noise_m);
  d["start_rms"] = number(e.start_residual_rms_m * std::sqrt(3.0));
  d["jacobian"] = e.jacobian;
  d["start_chi_square_per_dof"] = number(e.start_chi_square_per_dof);
  d["stopped_at_start"] = e.stopped_at_start;
  d["stop_reason"] = e.stop_reason;
  d["warm_start"] = {{"modulus_matched", e.warm_start.modulus_matched},
                     {"damping_matched", e.warm_start.damping_matched},
                     {"youngs_modulus", e.warm_start.youngs_modulus_pa},
                     {"rayleigh_alpha", e.warm_start.rayleigh_alpha},
                     {"rayleigh_beta", e.warm_start.rayleigh_beta}};
  d["message"] = e.message;
}

// ---------------------------------------------------------------------------------------------
// Rest shape

void run_rest_shape(const FemRecordingProblem& problem, const RefineSettings& s, RefineProgress& progress,
                    RefineOutcome& out) {
  FemRecordingProblem with_material = problem;
  if (out.estimated.count("youngs_modulus") != 0) {
    // The fitted modulus (or map) is what the body sags with.
    with_material.mesh.youngs_modulus.assign(
        out.element_youngs_modulus_pa.data(),
        out.element_youngs_modulus_pa.data() + out.element_youngs_modulus_pa.size());
    with_material.known_parameters.push_back("youngs_modulus");
  }
  progress.stage("rest_shape, Newton on the sag equations");
  const RestShapeResult r = estimate_rest_shape(with_material, s.rest_frame);
  out.rest_shape = r;
  out.converged = out.converged && r.converged;
  if (out.element_youngs_modulus_pa.size() == 0) {
    const std::vector<double>& given = with_material.mesh.youngs_modulus;
    out.element_youngs_modulus_pa =
        given.empty() ? Eigen::VectorXd::Constant(ix(problem.mesh.tet_count()), problem.material.youngs_modulus_pa)
                      : Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(given.data(), ix(problem.mesh.tet_count())));
  }
  out.diagnostics["rest_shape"] = {{"converged", r.converged},
                                   {"frame", s.rest_frame},
                                   {"iterations", r.iterations},
                                   {"load_steps", r.load_steps},
                                   {"residual", r.residual_n},
                                   {"max_sag", r.max_sag_m},
                                   {"mean_sag", r.mean_sag_m},
                                   {"forward_check_max_error", number(r.forward_check_error_m)},
                                   {"forward_check_mean_error", number(r.forward_check_mean_error_m)},
                                   {"message", r.message}};
  if (!out.simulated.empty()) return;  // the material fit's frames are the ones shown
  // Alone: the fitted model is the estimated rest shape settled under gravity (no load on it:
  // exactly the observed shape).
  const Eigen::VectorXd& observed = problem.frames[uz(s.rest_frame)].observed_position_m;
  out.simulated.push_back({s.rest_frame, r.forward_position_m.size() != 0 ? r.forward_position_m : observed});
  out.simulated_rest_m = r.rest_position_m;
}

// ---------------------------------------------------------------------------------------------

void compute_rms(const FemRecordingProblem& problem, RefineOutcome& out) {
  double sum = 0, free_sum = 0;
  long pairs = 0, free_pairs = 0;
  for (const SimulatedFrame& s : out.simulated) {
    const FemFrame& frame = problem.frames[uz(s.frame)];
    for (int node : frame.observed_nodes) {
      const double d2 =
          (s.position_m.segment<3>(3 * ix(node)) - frame.observed_position_m.segment<3>(3 * ix(node))).squaredNorm();
      sum += d2;
      ++pairs;
      if (!contains(problem.fixed_nodes, node) && !contains(frame.driven_nodes, node)) {
        free_sum += d2;
        ++free_pairs;
      }
    }
  }
  out.rms_pairs = pairs;
  out.rms_m = pairs > 0 ? std::sqrt(sum / static_cast<double>(pairs)) : kNaN;
  out.free_rms_pairs = free_pairs;
  out.free_rms_m = free_pairs > 0 ? std::sqrt(free_sum / static_cast<double>(free_pairs)) : kNaN;
}

}  // namespace

RefineOutcome run_refine(const FemRecordingProblem& problem, const RefinePlan& plan, const RefineSettings& settings,
                         RefineProgress& progress) {
  RefineOutcome out;
  out.simulated_rest_m = mesh_points(problem.mesh);
  if (plan.estimator) {
    switch (*plan.estimator) {
      case RefineEstimator::force: run_force(problem, settings, progress, out); break;
      case RefineEstimator::reaction: run_reaction(problem, settings, progress, out); break;
      case RefineEstimator::trajectory: run_trajectory(problem, plan, settings, progress, out); break;
    }
  }
  if (plan.rest_shape) run_rest_shape(problem, settings, progress, out);
  if (!problem.is_known("poisson_ratio")) out.assumed["poisson_ratio"] = problem.material.poisson_ratio;
  const bool mass_matters = (plan.estimator && *plan.estimator == RefineEstimator::trajectory) ||
                            (problem.gravity_declared && problem.material.gravity_m_s2.squaredNorm() > 0);
  if (mass_matters && !problem.is_known("density")) out.assumed["density"] = problem.material.density_kg_m3;
  compute_rms(problem, out);
  return out;
}

}  // namespace pliant::cli
