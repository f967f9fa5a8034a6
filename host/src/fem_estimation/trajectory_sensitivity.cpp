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
  bool have_force = false;
  for (std::size_t j = 0; j < parameters_.size(); ++j) {
    Eigen::VectorXd& s = position_[j];
    Eigen::VectorXd& sv = velocity_[j];
    Eigen::VectorXd& sa = acceleration_[j];
    u_ = c_d * s + c_dv * sv;
    mass_times(model, (1.0 + alpha * c_d) * s + (h + alpha * c_dv) * sv + c_a * sa, rhs_);
    switch (parameters_[j]) {
      case SensitivityParameter::log_youngs_modulus:
        // - dR/dlogE = c_f f_int(x+) - beta K w.
        if (!have_force) {
          force_.setZero(model.dof_count());
          dynamic.add_internal_force(end_m, 1.0, force_);
          have_force = true;
        }
        rhs_ += c_f * force_;
        if (beta > 0) dynamic.add_tangent_product(end_m, u_ - w_, beta, rhs_);
        break;
      case SensitivityParameter::log_rayleigh_alpha:
        // - dR/dlog alpha = -alpha M w.
        mass_times(model, w_, kw_);
        rhs_ -= alpha * kw_;
        if (beta > 0) dynamic.add_tangent_product(end_m, u_, beta, rhs_);
        break;
      case SensitivityParameter::log_rayleigh_beta:
        // - dR/dlog beta = -beta K w.
        if (beta > 0) dynamic.add_tangent_product(end_m, u_ - w_, beta, rhs_);
        break;
    }
    dynamic.solve_last_factorized(rhs_);  // S+ (zero at constrained nodes)
    const Eigen::VectorXd change = rhs_ - s;
    sa = (4.0 / (h * h)) * (change - h * sv) - sa;
    sv = (2.0 / h) * change - sv;
    s = rhs_;
  }
}

}  // namespace pliant::host::fem::detail
