// Forward sensitivities through the Newmark step (trajectory_sensitivity.hpp).
#include "trajectory_sensitivity.hpp"

#include <utility>

namespace pliant::host::fem::detail {
namespace {

// out = M v per node (lumped masses), at every node.
void mass_times(const FemModel& model, const Eigen::VectorXd& v, Eigen::VectorXd& out) {
  out.resize(v.size());
  for (int node = 0; node < model.node_count(); ++node) {
    out.segment<3>(3 * node) = model.lumped_mass_kg()[node] * v.segment<3>(3 * node);
  }
}

}  // namespace

TrajectorySensitivity::TrajectorySensitivity(std::vector<SensitivityParameter> parameters)
    : parameters_(std::move(parameters)),
      position_(parameters_.size()),
      velocity_(parameters_.size()),
      acceleration_(parameters_.size()) {}

void TrajectorySensitivity::start(FemSolver* fill, FemSolver& dynamic, const Eigen::VectorXd& position_m) {
  const FemModel& model = dynamic.model();
  const Eigen::Index dofs = model.dof_count();
  for (std::size_t j = 0; j < parameters_.size(); ++j) {
    position_[j].setZero(dofs);
    velocity_[j].setZero(dofs);
    acceleration_[j].setZero(dofs);
    if (parameters_[j] != SensitivityParameter::log_youngs_modulus) continue;
    // The fill's equilibrium moves as K^-1 f_int (f_int proportional to E at fixed positions).
    if (fill != nullptr) {
      fill->add_internal_force(position_m, 1.0, position_[j]);
      fill->solve_last_factorized(position_[j]);
    }
    // Initial acceleration M a = f_int + f_ext + M g (at rest): M S_a = f_int - K S.
    force_.setZero(dofs);
    dynamic.add_internal_force(position_m, 1.0, force_);
    dynamic.add_tangent_product(position_m, position_[j], -1.0, force_);
    for (int node = 0; node < model.node_count(); ++node) {
      if (dynamic.is_constrained(node)) continue;
      acceleration_[j].segment<3>(3 * node) = force_.segment<3>(3 * node) / model.lumped_mass_kg()[node];
    }
  }
}

void TrajectorySensitivity::substep(FemSolver& dynamic, const Eigen::VectorXd& start_m,
                                    const Eigen::VectorXd& velocity_before_m_s, const Eigen::VectorXd& end_m,
                                    double h) {
  const FemModel& model = dynamic.model();
  const double alpha = model.rayleigh_alpha();
  const double beta = model.rayleigh_beta();
  const double c_d = 0.5 * h;
  const double c_dv = 0.25 * h * h;
  const double c_a = 0.25 * h * h;
  const double c_f = 0.25 * h * h;
  // The damping argument of the step (driven nodes with the secant velocity).
  w_ = c_d * (end_m - start_m) - c_dv * velocity_before_m_s;
  for (int node : dynamic.driven_nodes()) w_.segment<3>(3 * node) = (c_f / h) * (end_m - start_m).segment<3>(3 * node);
  // Right-hand sides without the stiffness terms, and the vectors K multiplies (one fused pass).
  const std::size_t p = parameters_.size();
  rhs_.resize(p);
  product_.resize(p);
  next_.resize(p);
  bool need_force = false;
  for (std::size_t j = 0; j < p; ++j) {
    const Eigen::VectorXd& s = position_[j];
    const Eigen::VectorXd& sv = velocity_[j];
    const Eigen::VectorXd& sa = acceleration_[j];
    mass_times(model, (1.0 + alpha * c_d) * s + (h + alpha * c_dv) * sv + c_a * sa, rhs_[j]);
    product_[j] = c_d * s + c_dv * sv;  // beta K of this enters every right-hand side
    switch (parameters_[j]) {
      case SensitivityParameter::log_youngs_modulus:  // - dR/dlogE = c_f f_int(x+) - beta K w
        need_force = true;
        product_[j] -= w_;
        break;
      case SensitivityParameter::log_rayleigh_alpha:  // - dR/dlog alpha = -alpha M w
        mass_times(model, w_, kw_);
        rhs_[j] -= alpha * kw_;
        break;
      case SensitivityParameter::log_rayleigh_beta:  // - dR/dlog beta = -beta K w
        product_[j] -= w_;
        break;
    }
  }
  std::vector<const Eigen::VectorXd*> vectors;
  std::vector<double> scales;
  std::vector<Eigen::VectorXd*> outputs;
  if (beta > 0) {
    for (std::size_t j = 0; j < p; ++j) {
      vectors.push_back(&product_[j]);
      scales.push_back(beta);
      outputs.push_back(&rhs_[j]);
    }
  }
  if (need_force) force_.setZero(model.dof_count());
  dynamic.add_tangent_products(end_m, vectors, scales, outputs, c_f, need_force ? &force_ : nullptr);
  for (std::size_t j = 0; j < p; ++j) {
    if (parameters_[j] == SensitivityParameter::log_youngs_modulus) rhs_[j] += force_;
    next_[j] = rhs_[j];
    dynamic.solve_last_factorized(next_[j]);  // S+ with the step's matrix (zero at constrained nodes)
  }
  correct(dynamic, end_m, h);
  for (std::size_t j = 0; j < p; ++j) {
    Eigen::VectorXd& s = position_[j];
    Eigen::VectorXd& sv = velocity_[j];
    Eigen::VectorXd& sa = acceleration_[j];
    change_ = next_[j] - s;
    sa = (4.0 / (h * h)) * (change_ - h * sv) - sa;
    sv = (2.0 / h) * change_ - sv;
    s = next_[j];
  }
}

// One defect correction of S+ = A^-1 rhs: the step's matrix A drops the rotation derivative of
// the elastic tangent (and is taken at the predicted positions); the implicit step's own
// derivative is (1 + alpha c_d) M + c_f K_exact(x+) + beta c_d K(x+). S+ += A^-1 (rhs - that S+)
// leaves an error of the square of A's relative error.
void TrajectorySensitivity::correct(FemSolver& dynamic, const Eigen::VectorXd& end_m, double h) {
  const FemModel& model = dynamic.model();
  const double alpha = model.rayleigh_alpha();
  const double beta = model.rayleigh_beta();
  const double c_d = 0.5 * h;
  const double c_f = 0.25 * h * h;
  const std::size_t p = parameters_.size();
  std::vector<const Eigen::VectorXd*> vectors;
  std::vector<double> elastic, damping;
  std::vector<Eigen::VectorXd*> outputs;
  for (std::size_t j = 0; j < p; ++j) {
    mass_times(model, next_[j], kw_);
    rhs_[j] -= (1.0 + alpha * c_d) * kw_;
    vectors.push_back(&next_[j]);
    elastic.push_back(-c_f);
    damping.push_back(-beta * c_d);
    outputs.push_back(&rhs_[j]);
  }
  dynamic.add_tangent_products(end_m, vectors, elastic, outputs, 0.0, nullptr, true);
  if (beta > 0) dynamic.add_tangent_products(end_m, vectors, damping, outputs, 0.0, nullptr, false);
  for (std::size_t j = 0; j < p; ++j) {
    dynamic.solve_last_factorized(rhs_[j]);
    next_[j] += rhs_[j];
  }
}

}  // namespace pliant::host::fem::detail
