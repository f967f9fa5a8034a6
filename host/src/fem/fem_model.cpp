// FemModel precomputation and the element-level functions of fem_model.hpp.
#include "pliant/host/fem/fem_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Dense>

#include "fem_element.hpp"

namespace pliant::host::fem {

namespace {

std::size_t uz(int i) { return static_cast<std::size_t>(i); }

void check_material(const FemMaterial& m) {
  if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5)) {
    throw std::invalid_argument("FEM: poisson_ratio " + std::to_string(m.poisson_ratio) + " outside (-1, 0.5)");
  }
  if (!(m.density_kg_m3 > 0) || !std::isfinite(m.density_kg_m3)) {
    throw std::invalid_argument("FEM: density must be positive and finite");
  }
  if (!(m.rayleigh_alpha >= 0) || !(m.rayleigh_beta >= 0) || !std::isfinite(m.rayleigh_alpha) ||
      !std::isfinite(m.rayleigh_beta)) {
    throw std::invalid_argument("FEM: rayleigh_alpha and rayleigh_beta must be finite and >= 0");
  }
  if (!m.gravity_m_s2.allFinite()) throw std::invalid_argument("FEM: gravity must be finite");
}

void check_modulus(double e, const char* what) {
  if (!(e > 0) || !std::isfinite(e)) {
    throw std::invalid_argument(std::string("FEM: ") + what + " Young's modulus must be positive and finite");
  }
}

}  // namespace

FemModel::FemModel(const TetMesh& mesh, const FemMaterial& material) : material_(material) {
  if (mesh.points.empty() || mesh.tetrahedra.empty()) throw std::invalid_argument("FEM: empty mesh");
  if (mesh.points.size() % 3 != 0 || mesh.tetrahedra.size() % 4 != 0) {
    throw std::invalid_argument("FEM: mesh arrays are not 3 coordinates per point / 4 indices per tetrahedron");
  }
  check_material(material);
  node_count_ = mesh.point_count();
  const int m = mesh.tet_count();
  elements_.resize(uz(m));
  std::vector<char> used(uz(node_count_), 0);
  for (int e = 0; e < m; ++e) {
    for (int a = 0; a < 4; ++a) {
      const int node = mesh.tetrahedra[uz(4 * e + a)];
      if (node < 0 || node >= node_count_) {
        throw std::invalid_argument("FEM: tetrahedron " + std::to_string(e) + " has node index " +
                                    std::to_string(node) + " out of range");
      }
      elements_[uz(e)][uz(a)] = node;
      used[uz(node)] = 1;
    }
  }
  for (int i = 0; i < node_count_; ++i) {
    if (used[uz(i)] == 0) throw std::invalid_argument("FEM: node " + std::to_string(i) + " belongs to no tetrahedron");
  }
  if (!mesh.youngs_modulus.empty()) {
    if (static_cast<int>(mesh.youngs_modulus.size()) != m) {
      throw std::invalid_argument("FEM: mesh youngs_modulus has " + std::to_string(mesh.youngs_modulus.size()) +
                                  " values for " + std::to_string(m) + " tetrahedra");
    }
    youngs_ = Eigen::Map<const Eigen::VectorXd>(mesh.youngs_modulus.data(), m);
    for (int e = 0; e < m; ++e) check_modulus(youngs_[e], "per-element");
  } else {
    check_modulus(material.youngs_modulus_pa, "global");
    youngs_ = Eigen::VectorXd::Constant(m, material.youngs_modulus_pa);
  }
  const Eigen::VectorXd rest = Eigen::Map<const Eigen::VectorXd>(mesh.points.data(), 3 * node_count_);
  precompute_geometry(rest);
  build_node_stars();
  material_.volumetric = resolved_volumetric(material_);
  nodal_volumetric_ = material_.volumetric == FemVolumetric::nodal_average;
  update_lame();
}

void FemModel::build_node_stars() {
  node_element_offsets_.assign(uz(node_count_) + 1, 0);
  for (const auto& nodes : elements_) {
    for (int node : nodes) ++node_element_offsets_[uz(node) + 1];
  }
  for (int a = 0; a < node_count_; ++a) node_element_offsets_[uz(a) + 1] += node_element_offsets_[uz(a)];
  node_elements_.assign(uz(node_element_offsets_.back()), 0);
  std::vector<int> fill(node_element_offsets_.begin(), node_element_offsets_.end() - 1);
  for (int e = 0; e < element_count(); ++e) {
    for (int node : elements_[uz(e)]) node_elements_[uz(fill[uz(node)]++)] = e;
  }
}

void FemModel::precompute_geometry(const Eigen::VectorXd& rest) {
  if (rest.size() != 3 * node_count_) throw std::invalid_argument("FEM: rest positions must have 3n entries");
  if (!rest.allFinite()) throw std::invalid_argument("FEM: non-finite rest coordinates");
  const int m = element_count();
  Eigen::VectorXd volume(m);
  std::vector<Eigen::Matrix<double, 3, 4>> gradients(uz(m));
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(node_count_);
  for (int e = 0; e < m; ++e) {
    const auto& n = elements_[uz(e)];
    Eigen::Matrix3d dm;
    double longest = 0;
    for (int a = 0; a < 3; ++a) dm.col(a) = rest.segment<3>(3 * n[uz(a + 1)]) - rest.segment<3>(3 * n[0]);
    for (int a = 0; a < 4; ++a) {
      for (int b = a + 1; b < 4; ++b) {
        longest = std::max(longest, (rest.segment<3>(3 * n[uz(a)]) - rest.segment<3>(3 * n[uz(b)])).norm());
      }
    }
    const double v = dm.determinant() / 6.0;
    if (!(v > 1e-12 * longest * longest * longest)) {
      throw std::invalid_argument("FEM: tetrahedron " + std::to_string(e) + " has " +
                                  (v < 0 ? "negative" : "zero or negligible") + " volume " + std::to_string(v) +
                                  " m^3 (corners must be positively oriented)");
    }
    volume[e] = v;
    const Eigen::Matrix3d inv = dm.inverse();
    Eigen::Matrix<double, 3, 4>& b = gradients[uz(e)];
    for (int a = 0; a < 3; ++a) b.col(a + 1) = inv.row(a).transpose();
    b.col(0) = -(b.col(1) + b.col(2) + b.col(3));
    for (int a = 0; a < 4; ++a) mass[n[uz(a)]] += 0.25 * material_.density_kg_m3 * v;
  }
  rest_ = rest;
  volume_ = std::move(volume);
  gradients_ = std::move(gradients);
  node_volume_ = mass / material_.density_kg_m3;
  mass_ = std::move(mass);
}

void FemModel::update_node_bulk() {
  node_bulk_.setZero(node_count_);
  if (!nodal_volumetric_) return;
  const double unit_kappa = unit_lambda_ + 2.0 * unit_mu_ / 3.0;
  for (int e = 0; e < element_count(); ++e) {
    for (int node : elements_[uz(e)]) node_bulk_[node] += 0.25 * volume_[e] * youngs_[e] * unit_kappa;
  }
  node_bulk_.array() /= node_volume_.array();
}

void FemModel::update_lame() {
  const double nu = material_.poisson_ratio;
  unit_mu_ = 1.0 / (2.0 * (1.0 + nu));
  unit_lambda_ = nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  update_node_bulk();
}

FemVolumetric resolved_volumetric(const FemMaterial& material) {
  if (material.volumetric != FemVolumetric::automatic) return material.volumetric;
  return material.poisson_ratio >= kNodalAverageFromPoisson ? FemVolumetric::nodal_average : FemVolumetric::element;
}

const char* to_string(FemVolumetric volumetric) {
  switch (volumetric) {
    case FemVolumetric::automatic: return "automatic";
    case FemVolumetric::element: return "element";
    case FemVolumetric::nodal_average: return "nodal_average";
  }
  return "unknown";
}

Eigen::Matrix<double, 12, 12> FemModel::unit_element_stiffness(int element) const {
  if (element < 0 || element >= element_count()) throw std::invalid_argument("FEM: element index out of range");
  const auto& b = gradients_[uz(element)];
  Eigen::Matrix<double, 12, 12> k;
  for (int a = 0; a < 4; ++a) {
    for (int c = 0; c < 4; ++c) {
      k.block<3, 3>(3 * a, 3 * c) =
          detail::rotated_stiffness_block(b, b, a, c, volume_[element], unit_mu_, unit_element_lambda());
    }
  }
  return k;
}

void FemModel::set_youngs_modulus(double youngs_modulus_pa) {
  check_modulus(youngs_modulus_pa, "global");
  youngs_.setConstant(youngs_modulus_pa);
  update_node_bulk();
}

void FemModel::set_youngs_modulus(const Eigen::Ref<const Eigen::VectorXd>& per_element_pa) {
  if (per_element_pa.size() != element_count()) {
    throw std::invalid_argument("FEM: set_youngs_modulus needs one value per element");
  }
  for (Eigen::Index e = 0; e < per_element_pa.size(); ++e) check_modulus(per_element_pa[e], "per-element");
  youngs_ = per_element_pa;
  update_node_bulk();
}

void FemModel::set_poisson_ratio(double poisson_ratio) {
  FemMaterial next = material_;
  next.poisson_ratio = poisson_ratio;
  check_material(next);
  material_ = next;
  update_lame();
}

void FemModel::set_density(double density_kg_m3) {
  FemMaterial next = material_;
  next.density_kg_m3 = density_kg_m3;
  check_material(next);
  material_ = next;
  mass_.setZero();
  for (int e = 0; e < element_count(); ++e) {
    for (int node : elements_[uz(e)]) mass_[node] += 0.25 * density_kg_m3 * volume_[e];
  }
}

void FemModel::set_rayleigh(double rayleigh_alpha, double rayleigh_beta) {
  FemMaterial next = material_;
  next.rayleigh_alpha = rayleigh_alpha;
  next.rayleigh_beta = rayleigh_beta;
  check_material(next);
  material_ = next;
}

void FemModel::set_gravity(const Eigen::Vector3d& gravity_m_s2) {
  FemMaterial next = material_;
  next.gravity_m_s2 = gravity_m_s2;
  check_material(next);
  material_ = next;
}

void FemModel::set_rest_position(const Eigen::Ref<const Eigen::VectorXd>& rest_m) {
  precompute_geometry(rest_m);  // commits only after every element passed
  update_node_bulk();
}

Eigen::Matrix3d polar_rotation(const Eigen::Matrix3d& f) {
  if (!f.allFinite()) return Eigen::Matrix3d::Identity();
  const double norm2 = f.squaredNorm();
  if (!(norm2 > 0)) return Eigen::Matrix3d::Identity();
  Eigen::Matrix3d x = f * std::sqrt(3.0 / norm2);  // Frobenius norm sqrt(3), as a rotation's
  // Newton's iteration X <- (g X + X^-T / g) / 2 converges quadratically to the polar factor of
  // any non-singular matrix; the Frobenius scaling g speeds up the first steps of a strongly
  // stretched element. A positive determinant keeps the limit a proper rotation. Nearly singular
  // or inverted matrices go to the SVD, which handles rank deficiency. X^-T = cof(X) / det(X).
  if (x.determinant() > 1e-4) {
    bool scaled = true;
    for (int it = 0; it < 40; ++it) {
      Eigen::Matrix3d cof;
      cof.col(0) = x.col(1).cross(x.col(2));
      cof.col(1) = x.col(2).cross(x.col(0));
      cof.col(2) = x.col(0).cross(x.col(1));
      const double inv_det = 1.0 / x.col(0).dot(cof.col(0));
      double a = 0.5;
      double b = 0.5 * inv_det;
      if (scaled) {
        const double g = std::sqrt(std::sqrt(cof.squaredNorm() * inv_det * inv_det / x.squaredNorm()));
        a *= g;
        b /= g;
      }
      const Eigen::Matrix3d next = a * x + b * cof;
      const double step2 = (next - x).squaredNorm();
      x = next;
      if (step2 < 1e-4) scaled = false;
      // The error after a step is about step^2 / 2: below 1e-7 it is at rounding level.
      if (step2 < 1e-14) return x;
    }
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  const Eigen::Matrix3d v = svd.matrixV();
  if ((u * v.transpose()).determinant() < 0) u.col(2) = -u.col(2);  // reflection onto the smallest value
  return u * v.transpose();
}

Eigen::Matrix3d deformation_gradient(const FemModel& model, int element,
                                     const Eigen::Ref<const Eigen::VectorXd>& position_m) {
  if (element < 0 || element >= model.element_count()) throw std::invalid_argument("FEM: element index out of range");
  if (position_m.size() != model.dof_count()) throw std::invalid_argument("FEM: positions must have 3n entries");
  return detail::gather_gradient(position_m.data(), model.elements()[uz(element)], model.shape_gradients(element));
}

namespace {

// Rotations of every element at x and, for the nodal formulation, the nodal pressures.
struct ElementRotations {
  std::vector<Eigen::Matrix3d> rotation;
  std::vector<Eigen::Matrix3d> gradient;
  Eigen::VectorXd dilatation;     // m entries, nodal formulation only
  Eigen::VectorXd node_pressure;  // n entries, nodal formulation only
};

ElementRotations element_rotations(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& position_m) {
  if (position_m.size() != model.dof_count()) throw std::invalid_argument("FEM: positions must have 3n entries");
  ElementRotations out;
  const int m = model.element_count();
  out.rotation.resize(uz(m));
  out.gradient.resize(uz(m));
  for (int e = 0; e < m; ++e) {
    out.gradient[uz(e)] = detail::gather_gradient(position_m.data(), model.elements()[uz(e)], model.shape_gradients(e));
    out.rotation[uz(e)] = polar_rotation(out.gradient[uz(e)]);
  }
  if (model.nodal_volumetric()) {
    out.dilatation.resize(m);
    for (int e = 0; e < m; ++e) out.dilatation[e] = detail::dilatation(out.gradient[uz(e)], out.rotation[uz(e)]);
    out.node_pressure.resize(model.node_count());
    detail::nodal_pressure(model, out.dilatation.data(), out.node_pressure.data());
  }
  return out;
}

// sum_a (kappa_a / V_a) g_a g_a^T, g_a = sum_{e at a} (V_e / 4) R_e b_e, as the product
// G^T W G of the n x 3n matrix G whose row a is g_a^T (about 3 x patch entries per row) and
// W = diag(kappa_a / V_a): memory stays that of the result, not of its repeated outer products.
Eigen::SparseMatrix<double> volumetric_tangent(const FemModel& model, const ElementRotations& state) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(uz(model.node_element_offsets().back()) * 12);
  for (int a = 0; a < model.node_count(); ++a) {
    for (int k = model.node_element_offsets()[uz(a)]; k < model.node_element_offsets()[uz(a) + 1]; ++k) {
      const int e = model.node_elements()[uz(k)];
      const detail::Mat34 c =
          (0.25 * model.element_volume_m3()[e]) * (state.rotation[uz(e)] * model.shape_gradients(e));
      for (int q = 0; q < 4; ++q) {
        for (int d = 0; d < 3; ++d) entries.emplace_back(a, 3 * model.elements()[uz(e)][uz(q)] + d, c(d, q));
      }
    }
  }
  Eigen::SparseMatrix<double> g(model.node_count(), model.dof_count());
  g.setFromTriplets(entries.begin(), entries.end());  // sums an element's repeated corners
  const Eigen::VectorXd weight = model.node_bulk_modulus_pa().cwiseQuotient(model.node_volume_m3());
  const Eigen::SparseMatrix<double> weighted = weight.asDiagonal() * g;
  return Eigen::SparseMatrix<double>(g.transpose() * weighted);
}

}  // namespace

void internal_force(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& position_m,
                    Eigen::VectorXd& force_n) {
  const ElementRotations state = element_rotations(model, position_m);
  force_n.setZero(model.dof_count());
  for (int e = 0; e < model.element_count(); ++e) {
    const auto& nodes = model.elements()[uz(e)];
    const auto& b = model.shape_gradients(e);
    const double youngs = model.youngs_modulus_pa()[e];
    const Eigen::Matrix3d& r = state.rotation[uz(e)];
    Eigen::Matrix3d p = detail::corotated_stress(state.gradient[uz(e)], r, youngs * model.unit_mu(),
                                                 youngs * model.unit_element_lambda(), nullptr);
    if (model.nodal_volumetric()) p += detail::element_pressure(nodes, state.node_pressure.data()) * r;
    const detail::Mat34 corner = (-model.element_volume_m3()[e]) * (p * b);
    for (int a = 0; a < 4; ++a) force_n.segment<3>(3 * nodes[uz(a)]) += corner.col(a);
  }
}

double elastic_energy(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& position_m) {
  const ElementRotations state = element_rotations(model, position_m);
  double energy = 0;
  for (int e = 0; e < model.element_count(); ++e) {
    const double youngs = model.youngs_modulus_pa()[e];
    double density = 0;
    detail::corotated_stress(state.gradient[uz(e)], state.rotation[uz(e)], youngs * model.unit_mu(),
                             youngs * model.unit_element_lambda(), &density);
    energy += model.element_volume_m3()[e] * density;
  }
  if (model.nodal_volumetric()) {
    // sum_a V_a kappa_a theta_a^2 / 2 with p_a = kappa_a theta_a.
    for (int a = 0; a < model.node_count(); ++a) {
      const double p = state.node_pressure[a];
      const double kappa = model.node_bulk_modulus_pa()[a];
      if (kappa > 0) energy += 0.5 * model.node_volume_m3()[a] * p * p / kappa;
    }
  }
  return energy;
}

double kinetic_energy(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& velocity_m_s) {
  if (velocity_m_s.size() != model.dof_count()) throw std::invalid_argument("FEM: velocities must have 3n entries");
  double energy = 0;
  for (int i = 0; i < model.node_count(); ++i) {
    energy += 0.5 * model.lumped_mass_kg()[i] * velocity_m_s.segment<3>(3 * i).squaredNorm();
  }
  return energy;
}

double gravity_energy(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& position_m) {
  if (position_m.size() != model.dof_count()) throw std::invalid_argument("FEM: positions must have 3n entries");
  double energy = 0;
  for (int i = 0; i < model.node_count(); ++i) {
    energy -= model.lumped_mass_kg()[i] * model.gravity_m_s2().dot(position_m.segment<3>(3 * i));
  }
  return energy;
}

Eigen::SparseMatrix<double> stiffness_matrix(const FemModel& model,
                                             const Eigen::Ref<const Eigen::VectorXd>& position_m) {
  const ElementRotations state = element_rotations(model, position_m);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(uz(144 * model.element_count()));
  for (int e = 0; e < model.element_count(); ++e) {
    const auto& nodes = model.elements()[uz(e)];
    const auto& b = model.shape_gradients(e);
    const detail::Mat34 c = state.rotation[uz(e)] * b;
    const double youngs = model.youngs_modulus_pa()[e];
    for (int a = 0; a < 4; ++a) {
      for (int q = 0; q < 4; ++q) {
        const Eigen::Matrix3d k = detail::rotated_stiffness_block(
            c, b, a, q, model.element_volume_m3()[e], youngs * model.unit_mu(), youngs * model.unit_element_lambda());
        for (int i = 0; i < 3; ++i) {
          for (int j = 0; j < 3; ++j) triplets.emplace_back(3 * nodes[uz(a)] + i, 3 * nodes[uz(q)] + j, k(i, j));
        }
      }
    }
  }
  Eigen::SparseMatrix<double> k(model.dof_count(), model.dof_count());
  k.setFromTriplets(triplets.begin(), triplets.end());
  if (model.nodal_volumetric()) k += volumetric_tangent(model, state);
  return k;
}

Eigen::SparseMatrix<double> volumetric_stiffness_matrix(const FemModel& model,
                                                        const Eigen::Ref<const Eigen::VectorXd>& position_m) {
  const ElementRotations state = element_rotations(model, position_m);
  if (model.nodal_volumetric()) return volumetric_tangent(model, state);
  return Eigen::SparseMatrix<double>(model.dof_count(), model.dof_count());
}

Eigen::VectorXd element_pressure_pa(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& position_m) {
  if (position_m.size() != model.dof_count()) throw std::invalid_argument("FEM: positions must have 3n entries");
  Eigen::VectorXd pressure = Eigen::VectorXd::Zero(model.element_count());
  if (!model.nodal_volumetric()) return pressure;
  const ElementRotations state = element_rotations(model, position_m);
  for (int e = 0; e < model.element_count(); ++e) {
    pressure[e] = detail::element_pressure(model.elements()[uz(e)], state.node_pressure.data());
  }
  return pressure;
}

}  // namespace pliant::host::fem
