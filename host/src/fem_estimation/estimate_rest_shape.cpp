// Rest-shape estimation from a static shape under gravity (contract in estimate_rest_shape.hpp).
#include "pliant/host/fem/estimate_rest_shape.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

namespace pliant::host::fem {

namespace {

using Mat34 = Eigen::Matrix<double, 3, 4>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Vec12 = Eigen::Matrix<double, 12, 1>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr char kWho[] = "estimate_rest_shape: ";

std::size_t uz(int i) { return static_cast<std::size_t>(i); }

// Corner loads of one element (elastic force at observed corners x for rest corners `rest`, plus
// a quarter of the element's weight, density x rest volume, per corner). The same formula as
// internal_force and the lumped mass of fem_model.cpp; the residual is always evaluated with
// those library functions, this copy only feeds the Jacobian, where a small mismatch would cost
// convergence speed, never accuracy.
// `pressure`: the nodal formulation's element pressure (Pa), held fixed; 0 for the element one.
Mat34 element_load(const Mat34& rest, const Mat34& x, double mu, double lambda, double pressure, double density,
                   const Eigen::Vector3d& gravity) {
  Eigen::Matrix3d dm;
  Eigen::Matrix3d ds;
  for (int a = 0; a < 3; ++a) {
    dm.col(a) = rest.col(a + 1) - rest.col(0);
    ds.col(a) = x.col(a + 1) - x.col(0);
  }
  const double volume = dm.determinant() / 6.0;
  const Eigen::Matrix3d dm_inv = dm.inverse();
  const Eigen::Matrix3d f = ds * dm_inv;
  const Eigen::Matrix3d r = polar_rotation(f);
  Eigen::Matrix3d strain = r.transpose() * f;
  strain = 0.5 * (strain + strain.transpose());
  strain.diagonal().array() -= 1.0;
  Eigen::Matrix3d stress = 2.0 * mu * strain;
  stress.diagonal().array() += lambda * strain.trace() + pressure;
  Mat34 b;
  b.rightCols<3>() = dm_inv.transpose();
  b.col(0) = -(b.col(1) + b.col(2) + b.col(3));
  Mat34 load = (-volume) * (r * stress) * b;
  load.colwise() += (0.25 * density * volume) * gravity;
  return load;
}

Mat34 gather(const Eigen::VectorXd& v, const std::array<int, 4>& nodes) {
  Mat34 out;
  for (int a = 0; a < 4; ++a) out.col(a) = v.segment<3>(3 * nodes[uz(a)]);
  return out;
}

double max_abs(const Eigen::VectorXd& v) { return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff(); }

// Everything one estimation needs: a private model whose rest shape is moved around, the
// free-DOF numbering, the observed shape and the loads.
class RestShapeSolver {
 public:
  RestShapeSolver(const FemModel& model_template, const std::vector<int>& fixed_nodes,
                  const Eigen::VectorXd& static_shape, const RestShapeOptions& options)
      : model_(model_template), fixed_(fixed_nodes), observed_(static_shape), options_(options) {
    const int n = model_.node_count();
    if (static_shape.size() != 3 * n) {
      throw std::invalid_argument(std::string(kWho) + "static shape has " + std::to_string(static_shape.size()) +
                                  " entries, the mesh needs 3 x " + std::to_string(n));
    }
    for (int i = 0; i < n; ++i) {
      if (!static_shape.segment<3>(3 * i).allFinite()) {
        throw std::invalid_argument(std::string(kWho) + "static shape of node " + std::to_string(i) + " is not finite");
      }
    }
    if (options.max_iterations < 1) throw std::invalid_argument(std::string(kWho) + "max_iterations must be >= 1");
    if (!(options.force_tolerance_n >= 0) || !std::isfinite(options.force_tolerance_n) ||
        !(options.position_tolerance_m >= 0) || !std::isfinite(options.position_tolerance_m)) {
      throw std::invalid_argument(std::string(kWho) + "tolerances must be finite and >= 0");
    }
    external_ = options.external_force_n.size() == 0 ? Eigen::VectorXd::Zero(3 * n) : options.external_force_n;
    if (external_.size() != 3 * n || !external_.allFinite()) {
      throw std::invalid_argument(std::string(kWho) + "external_force_n must be empty or 3n finite values");
    }
    is_fixed_.assign(uz(n), 0);
    for (int node : fixed_) {
      if (node < 0 || node >= n) {
        throw std::invalid_argument(std::string(kWho) + "fixed node " + std::to_string(node) + " out of range");
      }
      if (is_fixed_[uz(node)] != 0) {
        throw std::invalid_argument(std::string(kWho) + "fixed node " + std::to_string(node) + " listed twice");
      }
      is_fixed_[uz(node)] = 1;
    }
    try {
      model_.set_rest_position(observed_);  // also the orientation check of the observed shape
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string(kWho) + "static shape: " + e.what());
    }
    dof_.assign(uz(3 * n), -1);
    for (int i = 0; i < n; ++i) {
      if (is_fixed_[uz(i)] != 0) continue;
      for (int a = 0; a < 3; ++a) dof_[uz(3 * i + a)] = free_dofs_++;
    }
    const Eigen::Vector3d lo = observed_.reshaped(3, n).rowwise().minCoeff();
    const Eigen::Vector3d hi = observed_.reshaped(3, n).rowwise().maxCoeff();
    diagonal_m_ = (hi - lo).norm();
  }

  RestShapeResult run() {
    RestShapeResult result;
    Eigen::VectorXd rest = observed_;
    Eigen::VectorXd r;
    evaluate(rest, 1.0, r);  // valid: checked in the constructor
    result.initial_residual_n = max_abs(r);
    check_supports();

    double largest_load = 0;
    for (int i = 0; i < model_.node_count(); ++i) {
      if (is_fixed_[uz(i)] != 0) continue;
      const Eigen::Vector3d load = model_.lumped_mass_kg()[i] * model_.gravity_m_s2() + external_.segment<3>(3 * i);
      largest_load = std::max(largest_load, load.norm());
    }
    force_tol_ = options_.force_tolerance_n > 0 ? options_.force_tolerance_n : 1e-9 * largest_load;
    position_tol_ = options_.position_tolerance_m > 0 ? options_.position_tolerance_m : 1e-10 * diagonal_m_;

    if (largest_load == 0 || free_dofs_ == 0) {
      result.converged = true;
      result.message = "no load on the free nodes: the rest shape is the observed shape (no forward check needed)";
      unloaded_ = true;
    } else if (options_.method == RestShapeMethod::fixed_point) {
      run_fixed_point(rest, result);
    } else {
      run_newton(rest, result);
    }
    evaluate(rest, 1.0, r);
    finish(rest, r, result);
    return result;
  }

 private:
  enum class Stage { converged, failed, out_of_iterations };

  // Newton with load continuation: r_lambda(X) = f_int(x_s; X) + lambda (M(X) g + f_ext) = 0 is
  // solved for lambda rising from 0 (where X = x_s) to 1, each stage starting from the previous
  // one's X. The first try is lambda = 1 directly; a stage that fails quarters the increment and
  // retries from the last converged X, a stage that succeeds doubles it. Large sag needs this: the first Newton step
  // from X = x_s "unbends" the body linearly, and for rotations of tens of degrees that step lands where the Jacobian
  // no longer describes r.
  void run_newton(Eigen::VectorXd& rest, RestShapeResult& result) {
    double lambda = 0;
    double increment = 1;
    while (true) {
      const double target = std::min(1.0, lambda + increment);
      const bool last = target >= 1.0;
      Eigen::VectorXd trial = rest;
      const Stage stage = newton_stage(trial, last ? 1.0 : target, last, result);
      if (stage == Stage::converged) {
        rest = std::move(trial);
        ++result.load_steps;
        if (last) {
          result.converged = true;
          result.message += " after " + std::to_string(result.iterations) + " Newton iterations in " +
                            std::to_string(result.load_steps) + " load step(s)";
          return;
        }
        lambda = target;
        increment = std::min(2.0 * increment, 1.0 - lambda);
      } else if (stage == Stage::out_of_iterations) {
        if (last) rest = std::move(trial);
        result.message = "not converged in " + std::to_string(options_.max_iterations) +
                         " Newton iterations (reached load factor " + std::to_string(lambda) + ")";
        return;
      } else {
        increment *= 0.25;
        if (increment < 1e-3) {
          result.message = "load continuation stalled at load factor " + std::to_string(lambda) +
                           ": the observed shape may not be a stable equilibrium of any rest shape";
          return;
        }
      }
    }
  }

  // Newton iterations at a fixed load factor. Steps are damped by natural monotonicity
  // (Deuflhard): the correction recomputed at the trial point with the same factorization must
  // shrink, which measures the residual in metres. |r| in newtons is a poor merit here, dominated
  // by stiff stretching modes that rise on good steps (linearly "unbending" a bar stretches its
  // nearly unloaded tip elements). A stage fails when the damping would go below 1/16 (the
  // increment was too large) or it takes more than 12 iterations. Intermediate stages stop at a
  // looser position tolerance: they only provide the start of the next.
  Stage newton_stage(Eigen::VectorXd& rest, double load_factor, bool last, RestShapeResult& result) {
    const double position_tol = last ? position_tol_ : std::max(position_tol_, 1e-7 * diagonal_m_);
    Eigen::VectorXd r;
    evaluate(rest, load_factor, r);
    for (int k = 0;; ++k) {
      if (last && max_abs(r) <= force_tol_) {
        result.message = "force tolerance met";
        return Stage::converged;
      }
      if (result.iterations >= options_.max_iterations) return Stage::out_of_iterations;
      if (k >= 12) return Stage::failed;
      const Eigen::VectorXd step = newton_step(rest, r, load_factor);
      const double correction = step.norm();
      const double largest = max_abs(step);
      ++result.iterations;
      result.last_update_m = largest;
      Eigen::VectorXd trial;
      Eigen::VectorXd trial_r;
      bool accepted = false;
      for (double t = 1.0; t >= 1.0 / 16 && !accepted; t *= 0.5) {
        trial = rest;
        add_free(trial, t * step);
        accepted = evaluate(trial, load_factor, trial_r) &&
                   (largest <= position_tol || simplified_correction(trial_r) <= (1.0 - 0.25 * t) * correction);
      }
      if (largest <= position_tol) {  // the remaining error is below the tolerance either way
        if (accepted) rest = std::move(trial);
        result.message = "position tolerance met";
        return Stage::converged;
      }
      if (!accepted) return Stage::failed;
      rest = std::move(trial);
      r = std::move(trial_r);
    }
  }

  // Inverse sag: X <- X + (x_s - x_static(X)) on the free DOFs, the forward solve starting at x_s.
  void run_fixed_point(Eigen::VectorXd& rest, RestShapeResult& result) {
    Eigen::VectorXd r;
    evaluate(rest, 1.0, r);
    while (true) {
      if (max_abs(r) <= force_tol_) {
        result.converged = true;
        result.message = "force tolerance met after " + std::to_string(result.iterations) + " inverse-sag iterations";
        return;
      }
      if (result.iterations >= options_.max_iterations) {
        result.message = "not converged in " + std::to_string(options_.max_iterations) + " inverse-sag iterations";
        return;
      }
      if (!solve_forward(rest, observed_)) {
        result.message = "the forward static solve of an inverse-sag step failed: " + forward_error_;
        return;
      }
      Eigen::VectorXd step(free_dofs_);
      for (std::size_t k = 0; k < dof_.size(); ++k) {
        const auto i = static_cast<Eigen::Index>(k);
        if (dof_[k] >= 0) step[dof_[k]] = observed_[i] - forward_.position_m[i];
      }
      Eigen::VectorXd trial = rest;
      add_free(trial, step);
      if (!evaluate(trial, 1.0, r)) {
        result.message = "an inverse-sag step inverted a rest element";
        return;
      }
      rest = std::move(trial);
      ++result.iterations;
      result.last_update_m = max_abs(step);
      if (result.last_update_m <= position_tol_) {
        result.converged = true;
        result.message =
            "position tolerance met after " + std::to_string(result.iterations) + " inverse-sag iterations";
        return;
      }
    }
  }

  // A non-zero load needs supports that stop every rigid motion of every connected part of the
  // mesh: internal forces sum to zero (no balance without supports), and rotating X about a line
  // through collinear supports leaves f_int(x_s; X) unchanged (the rest shape would not be
  // unique, the Jacobian singular).
  void check_supports() const {
    const int n = model_.node_count();
    double load = 0;
    for (int i = 0; i < n; ++i) {
      if (is_fixed_[uz(i)] != 0) continue;
      load += (model_.lumped_mass_kg()[i] * model_.gravity_m_s2() + external_.segment<3>(3 * i)).norm();
    }
    if (load == 0 || free_dofs_ == 0) return;
    if (fixed_.empty()) {
      throw std::invalid_argument(std::string(kWho) +
                                  "no fixed nodes: internal forces sum to zero and cannot balance gravity or "
                                  "the external load, so no rest shape has this static shape");
    }
    // Connected parts (union-find over the elements' corners).
    std::vector<int> parent(uz(n));
    for (int i = 0; i < n; ++i) parent[uz(i)] = i;
    auto root = [&parent](int i) {
      while (parent[uz(i)] != i) i = parent[uz(i)] = parent[uz(parent[uz(i)])];
      return i;
    };
    for (const auto& nodes : model_.elements()) {
      for (int a = 1; a < 4; ++a) parent[uz(root(nodes[uz(a)]))] = root(nodes[0]);
    }
    std::vector<std::vector<int>> supports(uz(n));
    for (int node : fixed_) supports[uz(root(node))].push_back(node);
    for (int i = 0; i < n; ++i) {
      if (root(i) != i) continue;
      const std::vector<int>& held = supports[uz(i)];
      if (held.empty()) {
        throw std::invalid_argument(std::string(kWho) + "the part of the mesh containing node " + std::to_string(i) +
                                    " has no fixed nodes: nothing balances its load");
      }
      const Eigen::Vector3d p0 = observed_.segment<3>(3 * held[0]);
      Eigen::Vector3d axis = Eigen::Vector3d::Zero();
      for (int node : held) {
        const Eigen::Vector3d d = observed_.segment<3>(3 * node) - p0;
        if (d.norm() > axis.norm()) axis = d;
      }
      double off_axis = 0;
      if (axis.norm() > 0) {
        const Eigen::Vector3d u = axis.normalized();
        for (int node : held) {
          const Eigen::Vector3d d = observed_.segment<3>(3 * node) - p0;
          off_axis = std::max(off_axis, (d - d.dot(u) * u).norm());
        }
      }
      if (off_axis <= 1e-9 * diagonal_m_) {
        throw std::invalid_argument(std::string(kWho) + "the fixed nodes of the part containing node " +
                                    std::to_string(i) +
                                    " are fewer than three or collinear: they do not hold it against rigid "
                                    "rotation, so the rest shape is not unique");
      }
    }
  }

  void add_free(Eigen::VectorXd& rest, const Eigen::VectorXd& free_update) const {
    for (std::size_t k = 0; k < dof_.size(); ++k) {
      if (dof_[k] >= 0) rest[static_cast<Eigen::Index>(k)] += free_update[dof_[k]];
    }
  }

  // r(X) = f_int(x_s; X) + load_factor (M(X) g + f_ext) over the free DOFs, with the library's
  // own force and mass. False when X inverts or flattens an element (not a valid rest shape) or
  // the forces are not finite.
  bool evaluate(const Eigen::VectorXd& rest, double load_factor, Eigen::VectorXd& r) {
    try {
      model_.set_rest_position(rest);
    } catch (const std::invalid_argument&) {
      return false;
    }
    internal_force(model_, observed_, force_);
    r.resize(free_dofs_);
    const Eigen::VectorXd& mass = model_.lumped_mass_kg();
    for (int i = 0; i < model_.node_count(); ++i) {
      for (int a = 0; a < 3; ++a) {
        const int k = dof_[uz(3 * i + a)];
        if (k >= 0) {
          r[k] = force_[3 * i + a] + load_factor * (mass[i] * model_.gravity_m_s2()[a] + external_[3 * i + a]);
        }
      }
    }
    return r.allFinite();
  }

  // dr/dX of the nodal dilatations: with f_vol = -sum_a p_a g_a, p_a = kappa_a (V_a theta_a) / V_a
  // and d theta_e / dX_k = -S_e b_k (S = R^T F; from dF = -F dDm Dm^-1), the change of the
  // pressures gives sum_a (kappa_a / V_a) g_a h_a^T with g_a = sum_{e at a} (V_e / 4) R_e b_e and
  // h_a = sum_{e at a} (V_e / 4) S_e b_e (not symmetric). The change of g_a itself with X is left
  // to the element blocks' held pressure.
  // Assembled as the product G^T W H of the n x 3n matrices whose rows are g_a and h_a, with
  // W = diag(kappa_a / V_a), then restricted to the free DOFs.
  void add_volumetric_tangent(std::vector<Eigen::Triplet<double>>& triplets) const {
    const int n = model_.node_count();
    std::vector<Eigen::Triplet<double>> g_entries;
    std::vector<Eigen::Triplet<double>> h_entries;
    for (int a = 0; a < n; ++a) {
      for (int k = model_.node_element_offsets()[uz(a)]; k < model_.node_element_offsets()[uz(a) + 1]; ++k) {
        const int e = model_.node_elements()[uz(k)];
        const Eigen::Matrix3d f = deformation_gradient(model_, e, observed_);
        const Eigen::Matrix3d r = polar_rotation(f);
        const double quarter = 0.25 * model_.element_volume_m3()[e];
        const Mat34 g = quarter * (r * model_.shape_gradients(e));
        const Mat34 h = quarter * ((r.transpose() * f) * model_.shape_gradients(e));
        for (int q = 0; q < 4; ++q) {
          for (int d = 0; d < 3; ++d) {
            const int dof = 3 * model_.elements()[uz(e)][uz(q)] + d;
            g_entries.emplace_back(a, dof, g(d, q));
            h_entries.emplace_back(a, dof, h(d, q));
          }
        }
      }
    }
    Eigen::SparseMatrix<double> g(n, 3 * n);
    Eigen::SparseMatrix<double> h(n, 3 * n);
    g.setFromTriplets(g_entries.begin(), g_entries.end());
    h.setFromTriplets(h_entries.begin(), h_entries.end());
    const Eigen::VectorXd weight = model_.node_bulk_modulus_pa().cwiseQuotient(model_.node_volume_m3());
    const Eigen::SparseMatrix<double> weighted = weight.asDiagonal() * h;
    const Eigen::SparseMatrix<double> tangent = g.transpose() * weighted;
    for (int col = 0; col < tangent.outerSize(); ++col) {
      const int c = dof_[uz(col)];
      if (c < 0) continue;
      for (Eigen::SparseMatrix<double>::InnerIterator it(tangent, col); it; ++it) {
        const int row = dof_[uz(static_cast<int>(it.row()))];
        if (row >= 0) triplets.emplace_back(row, c, it.value());
      }
    }
  }

  // Newton direction -J^-1 r with J = dr/dX over the free DOFs, assembled from central
  // differences of the element loads in each element's own frame (coordinates relative to
  // corner 0, so the step is not lost against large absolute coordinates).
  Eigen::VectorXd newton_step(const Eigen::VectorXd& rest, const Eigen::VectorXd& r, double load_factor) {
    const Eigen::Vector3d gravity = load_factor * model_.gravity_m_s2();
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(uz(144 * model_.element_count()));
    const double density = model_.material().density_kg_m3;
    // Under the nodal formulation the element blocks carry the deviatoric stress and the
    // element's pressure held fixed (its change with the element's own rest geometry);
    // add_volumetric_tangent adds the change of the pressures. The model's rest shape is `rest`
    // already: newton_stage evaluated it last.
    const Eigen::VectorXd pressure = element_pressure_pa(model_, observed_);
    for (int e = 0; e < model_.element_count(); ++e) {
      const auto& nodes = model_.elements()[uz(e)];
      const double youngs = model_.youngs_modulus_pa()[e];
      const double mu = youngs * model_.unit_mu();
      const double lambda = youngs * model_.unit_element_lambda();
      Mat34 x = gather(observed_, nodes);
      x = x.colwise() - x.col(0).eval();
      Mat34 x_rest = gather(rest, nodes);
      x_rest = x_rest.colwise() - x_rest.col(0).eval();
      double longest = 0;
      for (int a = 0; a < 4; ++a) {
        for (int b = a + 1; b < 4; ++b) longest = std::max(longest, (x_rest.col(a) - x_rest.col(b)).norm());
      }
      const double h = 1e-5 * longest;
      Mat12 jac;
      for (int j = 0; j < 12; ++j) {
        Mat34 plus = x_rest;
        Mat34 minus = x_rest;
        plus(j % 3, j / 3) += h;
        minus(j % 3, j / 3) -= h;
        const Mat34 diff = element_load(plus, x, mu, lambda, pressure[e], density, gravity) -
                           element_load(minus, x, mu, lambda, pressure[e], density, gravity);
        jac.col(j) = Eigen::Map<const Vec12>(diff.data()) / (2.0 * h);
      }
      for (int a = 0; a < 4; ++a) {
        for (int i = 0; i < 3; ++i) {
          const int row = dof_[uz(3 * nodes[uz(a)] + i)];
          if (row < 0) continue;
          for (int b = 0; b < 4; ++b) {
            for (int c = 0; c < 3; ++c) {
              const int col = dof_[uz(3 * nodes[uz(b)] + c)];
              if (col >= 0) triplets.emplace_back(row, col, jac(3 * a + i, 3 * b + c));
            }
          }
        }
      }
    }
    if (model_.nodal_volumetric()) add_volumetric_tangent(triplets);
    Eigen::SparseMatrix<double> jacobian(free_dofs_, free_dofs_);
    jacobian.setFromTriplets(triplets.begin(), triplets.end());
    if (!lu_analyzed_) {  // the pattern never changes: order it once
      lu_.analyzePattern(jacobian);
      lu_analyzed_ = true;
    }
    lu_.factorize(jacobian);
    if (lu_.info() != Eigen::Success) {
      throw std::runtime_error(std::string(kWho) + "the Jacobian is singular (" + lu_.lastErrorMessage() +
                               "): a part of the mesh may not be connected to the fixed nodes");
    }
    Eigen::VectorXd step = lu_.solve(-r);
    if (lu_.info() != Eigen::Success || !step.allFinite()) {
      throw std::runtime_error(std::string(kWho) + "the Newton solve produced non-finite values");
    }
    return step;
  }

  // |J^-1 r| with the last factorization: the residual measured as a position correction.
  double simplified_correction(const Eigen::VectorXd& r) const {
    const Eigen::VectorXd correction = lu_.solve(r);
    return correction.allFinite() ? correction.norm() : std::numeric_limits<double>::infinity();
  }

  bool solve_forward(const Eigen::VectorXd& rest, const Eigen::VectorXd& start) {
    try {
      model_.set_rest_position(rest);
      if (!solver_) solver_.emplace(model_, fixed_, std::vector<int>{});
      forward_ = solver_->solve_static(Eigen::VectorXd(), external_, options_.static_options, start);
    } catch (const std::exception& e) {
      forward_error_ = e.what();
      return false;
    }
    return true;
  }

  void finish(const Eigen::VectorXd& rest, const Eigen::VectorXd& r, RestShapeResult& result) {
    const int n = model_.node_count();
    result.rest_position_m = rest;
    result.residual_n = max_abs(r);
    model_.set_rest_position(rest);
    result.total_mass_kg = model_.total_mass_kg();
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      const double d = (observed_.segment<3>(3 * i) - rest.segment<3>(3 * i)).norm();
      result.max_sag_m = std::max(result.max_sag_m, d);
      sum += d;
    }
    result.mean_sag_m = sum / n;
    result.forward_check_error_m = kNaN;
    result.forward_check_mean_error_m = kNaN;
    if (!options_.forward_check || unloaded_) return;
    // Start at the rest shape (empty start), as a user's simulation would.
    if (!solve_forward(rest, Eigen::VectorXd())) {
      result.message += "; forward check failed: " + forward_error_;
      return;
    }
    result.forward_check_converged = forward_.converged;
    double worst = 0;
    sum = 0;
    for (int i = 0; i < n; ++i) {
      const double d = (forward_.position_m.segment<3>(3 * i) - observed_.segment<3>(3 * i)).norm();
      worst = std::max(worst, d);
      sum += d;
    }
    result.forward_check_error_m = worst;
    result.forward_check_mean_error_m = sum / n;
    result.forward_position_m = forward_.position_m;
  }

  FemModel model_;
  std::vector<int> fixed_;
  Eigen::VectorXd observed_;
  RestShapeOptions options_;
  Eigen::VectorXd external_;
  std::vector<char> is_fixed_;
  std::vector<int> dof_;  // 3n: free DOF index or -1
  int free_dofs_ = 0;
  double diagonal_m_ = 0;
  double force_tol_ = 0;
  bool unloaded_ = false;
  double position_tol_ = 0;
  Eigen::VectorXd force_;
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu_;
  bool lu_analyzed_ = false;
  std::optional<FemSolver> solver_;
  FemStaticResult forward_;
  std::string forward_error_;
};

}  // namespace

RestShapeResult estimate_rest_shape(const FemModel& model_template, const std::vector<int>& fixed_nodes,
                                    const Eigen::VectorXd& static_shape_m, const RestShapeOptions& options) {
  RestShapeSolver solver(model_template, fixed_nodes, static_shape_m, options);
  return solver.run();
}

RestShapeResult estimate_rest_shape(const FemRecordingProblem& problem, int frame_index,
                                    const RestShapeOptions& options) {
  const std::string label = std::string(kWho) + "recording " + problem.name + ": ";
  if (frame_index < 0 || frame_index >= static_cast<int>(problem.frames.size())) {
    throw std::invalid_argument(label + "frame " + std::to_string(frame_index) + " out of range (" +
                                std::to_string(problem.frames.size()) + " frames)");
  }
  const FemFrame& frame = problem.frames[uz(frame_index)];
  const int n = problem.mesh.point_count();
  if (static_cast<int>(frame.observed_nodes.size()) != n) {
    throw std::invalid_argument(label + "frame " + std::to_string(frame_index) + " observes " +
                                std::to_string(frame.observed_nodes.size()) + " of " + std::to_string(n) +
                                " nodes; the rest shape needs every node");
  }
  if (!frame.driven_nodes.empty()) {
    throw std::invalid_argument(label + "node " + std::to_string(frame.driven_nodes.front()) + " is driven in frame " +
                                std::to_string(frame_index) +
                                " (unknown support force); use a frame where only gravity and the fixed nodes act");
  }
  if (!problem.gravity_declared) {
    throw std::invalid_argument(label + "the recording declares no gravity, so nothing makes the body sag");
  }
  if (!problem.is_known("youngs_modulus") && problem.mesh.youngs_modulus.empty()) {
    throw std::invalid_argument(label + "Young's modulus is not known (the sag scales with 1/E)");
  }
  if (!problem.is_known("density")) {
    throw std::invalid_argument(label + "density is not known (the sag scales with the density)");
  }
  const FemModel model(problem.mesh, problem.material);
  RestShapeOptions with_load = options;
  if (frame.has_wrench && !problem.applied_to.empty()) {
    if (with_load.external_force_n.size() == 0) with_load.external_force_n = Eigen::VectorXd::Zero(3 * n);
    if (with_load.external_force_n.size() != 3 * n) {
      throw std::invalid_argument(std::string(kWho) + "external_force_n must be empty or 3n finite values");
    }
    if (frame.wrench_torque_nm.norm() > 0 && problem.applied_to.size() >= 2) {
      add_spread_wrench(frame.wrench_force_n, frame.wrench_torque_nm, problem.applied_to, frame.observed_position_m,
                        with_load.external_force_n);
    } else {
      add_spread_force(frame.wrench_force_n, problem.applied_to, n, with_load.external_force_n);
    }
  }
  return estimate_rest_shape(model, problem.fixed_nodes, frame.observed_position_m, with_load);
}

}  // namespace pliant::host::fem
