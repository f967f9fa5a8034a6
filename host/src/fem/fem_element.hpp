// Element kernels shared by the model functions and the solvers (private to the host library).
#pragma once

#include <array>

#include <Eigen/Core>

#include "pliant/host/fem/fem_model.hpp"

namespace pliant::host::fem::detail {

using Mat34 = Eigen::Matrix<double, 3, 4>;

/// F = sum_a x_a b_a^T for corner positions taken from a 3n array.
inline Eigen::Matrix3d gather_gradient(const double* x, const std::array<int, 4>& nodes, const Mat34& b) {
  Eigen::Matrix3d f = Eigen::Matrix3d::Zero();
  for (int a = 0; a < 4; ++a) {
    const Eigen::Map<const Eigen::Vector3d> xa(x + 3 * nodes[static_cast<std::size_t>(a)]);
    f.noalias() += xa * b.col(a).transpose();
  }
  return f;
}

/// World-frame stress-like tensor of the element: P = R sigma(sym(R^T F) - I), so the corner
/// forces are -V P b_a. Also returns the strain energy density through `energy_density`.
inline Eigen::Matrix3d corotated_stress(const Eigen::Matrix3d& f, const Eigen::Matrix3d& r, double mu, double lambda,
                                        double* energy_density) {
  Eigen::Matrix3d strain = r.transpose() * f;
  strain = 0.5 * (strain + strain.transpose());
  strain.diagonal().array() -= 1.0;
  const double trace = strain.trace();
  if (energy_density != nullptr) *energy_density = mu * strain.squaredNorm() + 0.5 * lambda * trace * trace;
  Eigen::Matrix3d sigma = 2.0 * mu * strain;
  sigma.diagonal().array() += lambda * trace;
  return r * sigma;
}

/// Product of the rotated element stiffness R K_e R^T with corner vectors w_a, written as
/// out_a = V s c_a with c = R b (rotated gradients), s = mu (H + H^T) + lambda tr(H) I and
/// H = sum_a w_a c_a^T. Adds into `out` (3n array).
inline void add_rotated_stiffness_product(const Mat34& c, double volume, double mu, double lambda, const double* w,
                                          const std::array<int, 4>& nodes, double scale, double* out) {
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (int a = 0; a < 4; ++a) {
    const Eigen::Map<const Eigen::Vector3d> wa(w + 3 * nodes[static_cast<std::size_t>(a)]);
    h.noalias() += wa * c.col(a).transpose();
  }
  Eigen::Matrix3d s = mu * (h + h.transpose());
  s.diagonal().array() += lambda * h.trace();
  const Mat34 contribution = (scale * volume) * (s * c);
  for (int a = 0; a < 4; ++a) {
    Eigen::Map<Eigen::Vector3d> oa(out + 3 * nodes[static_cast<std::size_t>(a)]);
    oa += contribution.col(a);
  }
}

/// Product of the element's exact corotational tangent (the polar factor's derivative included,
/// which R K_e R^T drops) with corner vectors u_a: out_a += scale V dP b_a. With F = R S,
/// dF = sum u_a b_a^T and W = R^T dF: (tr(S) I - S) omega = axial(W - W^T), dR = R [omega]x,
/// dS = W - [omega]x S, and dP = R ([omega]x sigma(S - I) + sigma(dS)). Element formulation only.
inline void add_exact_stiffness_product(const Eigen::Matrix3d& f, const Eigen::Matrix3d& r, const Mat34& b,
                                        double volume, double mu, double lambda, const double* u,
                                        const std::array<int, 4>& nodes, double scale, double* out) {
  Eigen::Matrix3d s = r.transpose() * f;
  s = 0.5 * (s + s.transpose());
  const auto sigma = [mu, lambda](const Eigen::Matrix3d& strain) {
    Eigen::Matrix3d t = 2.0 * mu * strain;
    t.diagonal().array() += lambda * strain.trace();
    return t;
  };
  Eigen::Matrix3d df = Eigen::Matrix3d::Zero();
  for (int a = 0; a < 4; ++a) {
    df.noalias() +=
        Eigen::Map<const Eigen::Vector3d>(u + 3 * nodes[static_cast<std::size_t>(a)]) * b.col(a).transpose();
  }
  const Eigen::Matrix3d w = r.transpose() * df;
  const Eigen::Vector3d axial(w(2, 1) - w(1, 2), w(0, 2) - w(2, 0), w(1, 0) - w(0, 1));
  Eigen::Matrix3d g = -s;
  g.diagonal().array() += s.trace();
  const Eigen::Vector3d omega = g.inverse() * axial;
  Eigen::Matrix3d spin;
  spin << 0, -omega(2), omega(1), omega(2), 0, -omega(0), -omega(1), omega(0), 0;
  Eigen::Matrix3d ds = w - spin * s;
  ds = 0.5 * (ds + ds.transpose());
  Eigen::Matrix3d strain = s;
  strain.diagonal().array() -= 1.0;
  const Mat34 contribution = (scale * volume) * (r * (spin * sigma(strain) + sigma(ds)) * b);
  for (int a = 0; a < 4; ++a) {
    Eigen::Map<Eigen::Vector3d>(out + 3 * nodes[static_cast<std::size_t>(a)]) += contribution.col(a);
  }
}

/// Block (a, b) of R K_e R^T: V (lambda c_a c_b^T + mu c_b c_a^T + mu (b_a . b_b) I).
inline Eigen::Matrix3d rotated_stiffness_block(const Mat34& c, const Mat34& b, int ia, int ib, double volume, double mu,
                                               double lambda) {
  Eigen::Matrix3d k =
      (volume * lambda) * c.col(ia) * c.col(ib).transpose() + (volume * mu) * c.col(ib) * c.col(ia).transpose();
  k.diagonal().array() += volume * mu * b.col(ia).dot(b.col(ib));
  return k;
}

/// Dilatation of an element, theta = tr(R^T F) - 3: the trace of its corotated strain. Its
/// gradient with respect to corner a is exactly R b_a (the polar factor's derivative drops out of
/// d tr(S) = R : dF).
inline double dilatation(const Eigen::Matrix3d& f, const Eigen::Matrix3d& r) {
  return (r.transpose() * f).trace() - 3.0;
}

/// Nodal pressures of the averaged-nodal-pressure formulation (fem_model.hpp) from one value per
/// element (a dilatation, or its rate): p_a = kappa_a sum_{e at a} (V_e / 4) value_e / V_a.
/// element_value: m entries; node_pressure: n entries, overwritten. Allocation-free.
inline void nodal_pressure(const FemModel& model, const double* element_value, double* node_pressure) {
  const auto& offsets = model.node_element_offsets();
  const auto& stars = model.node_elements();
  for (int a = 0; a < model.node_count(); ++a) {
    double sum = 0;
    for (int k = offsets[static_cast<std::size_t>(a)]; k < offsets[static_cast<std::size_t>(a) + 1]; ++k) {
      const int e = stars[static_cast<std::size_t>(k)];
      sum += 0.25 * model.element_volume_m3()[e] * element_value[e];
    }
    node_pressure[a] = model.node_bulk_modulus_pa()[a] * sum / model.node_volume_m3()[a];
  }
}

/// The pressure an element feels: the mean of its corners' nodal pressures.
inline double element_pressure(const std::array<int, 4>& nodes, const double* node_pressure) {
  return 0.25 * (node_pressure[nodes[0]] + node_pressure[nodes[1]] + node_pressure[nodes[2]] + node_pressure[nodes[3]]);
}

}  // namespace pliant::host::fem::detail
