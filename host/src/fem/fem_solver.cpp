// Backward Euler, Newmark and static Newton solves of fem_solver.hpp.
#include "pliant/host/fem/fem_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Dense>

#include "fem_cholesky.hpp"
#include "fem_element.hpp"

namespace pliant::host::fem {

namespace {

std::size_t uz(int i) { return static_cast<std::size_t>(i); }

// Corner pairs (a <= b) of a tetrahedron: the blocks of the symmetric element matrix we store.
constexpr int kPairA[10] = {0, 1, 2, 3, 0, 0, 0, 1, 1, 2};
constexpr int kPairB[10] = {0, 1, 2, 3, 1, 2, 3, 2, 3, 3};

// Where block (a, b) of an element goes in the factor storage: the lower-triangle copy is block
// (a, b) itself, or block (b, a) when `swap`; column-major with leading dimension ld.
struct PairSlot {
  std::int64_t offset = -1;  // -1: a corner is constrained, the block is not assembled
  std::int32_t ld = 0;
  std::int32_t swap = 0;
};

void check_node_list(const std::vector<int>& nodes, int node_count, const char* what, std::vector<char>& seen) {
  for (int node : nodes) {
    if (node < 0 || node >= node_count) {
      throw std::invalid_argument(std::string("FemSolver: ") + what + " node " + std::to_string(node) +
                                  " out of range");
    }
    if (seen[uz(node)] != 0) {
      throw std::invalid_argument(std::string("FemSolver: ") + what + " node " + std::to_string(node) +
                                  " listed twice or both fixed and driven");
    }
    seen[uz(node)] = 1;
  }
}

}  // namespace

struct FemSolver::Impl {
  const FemModel& model;
  std::vector<int> free_index;   // node -> free index or -1
  std::vector<int> free_nodes;   // free index -> node
  std::vector<int> constrained;  // fixed then driven
  std::vector<int> boundary_elements;
  std::vector<PairSlot> pair_slots;         // 10 per element
  std::vector<std::int64_t> diagonal_slot;  // per free node
  std::vector<std::int32_t> diagonal_ld;
  detail::BlockCholesky cholesky;
  double length_scale = 1;

  // Averaged nodal pressure (model.nodal_volumetric() only). Node a's patch is the set of
  // corners of its elements; its volumetric tangent (kappa_a / V_a) g_a g_a^T couples every pair
  // of patch nodes. patch_nodes[patch_offsets[a] ..] lists them; star_corner_local holds, for
  // each (element at a, corner), the corner's position in a's patch (4 per entry of
  // model.node_elements()); pair_slots of node a (patch pairs i <= j, row-major over the
  // upper triangle) start at patch_pair_offsets[a].
  std::vector<int> patch_offsets;
  std::vector<int> patch_nodes;
  std::vector<int> star_corner_local;
  std::vector<std::int64_t> patch_pair_offsets;
  std::vector<PairSlot> patch_pair_slots;
  std::vector<Eigen::Matrix3d> rotations;  // per element, from the last nodal_pressure_pass
  Eigen::VectorXd dilatation;              // m: tr(R^T F) - 3
  Eigen::VectorXd dilatation_rate;         // m: linearised dilatation of the vector w
  Eigen::VectorXd node_pressure;           // n: kappa_a theta_a
  Eigen::VectorXd node_pressure_rate;      // n: the same for dilatation_rate
  Eigen::Matrix3Xd patch_gradient;         // 3 x (largest patch): g_a by patch node

  // Workspaces (3n unless noted).
  Eigen::VectorXd start;  // positions at the start of the substep
  Eigen::VectorXd x;
  Eigen::VectorXd residual;
  Eigen::VectorXd w;
  Eigen::VectorXd rhs;  // 3 * free nodes
  Eigen::VectorXd reaction;
  Eigen::VectorXd scratch;
  Eigen::VectorXd target;           // 3 * driven nodes
  Eigen::VectorXd previous_driven;  // 3 * driven nodes
  Eigen::VectorXd velocity_before;  // velocities at the start of the substep (driven nodes)
  Eigen::VectorXd sensitivity;      // 3n: output of the sensitivity helpers
  bool factorized = false;          // a factorization exists (solve_last_factorized)

  explicit Impl(const FemModel& m) : model(m) {}

  // Rotations of every element at xs, and the nodal pressures of xs and (when wv != nullptr) of
  // the linearised dilatation of wv. Nodal formulation only.
  void nodal_pressure_pass(const double* xs, const double* wv) {
    for (int e = 0; e < model.element_count(); ++e) {
      const auto& nodes = model.elements()[uz(e)];
      const detail::Mat34& b = model.shape_gradients(e);
      const Eigen::Matrix3d f = detail::gather_gradient(xs, nodes, b);
      rotations[uz(e)] = polar_rotation(f);
      dilatation[e] = detail::dilatation(f, rotations[uz(e)]);
      if (wv != nullptr)
        dilatation_rate[e] = (rotations[uz(e)].transpose() * detail::gather_gradient(wv, nodes, b)).trace();
    }
    detail::nodal_pressure(model, dilatation.data(), node_pressure.data());
    if (wv != nullptr) detail::nodal_pressure(model, dilatation_rate.data(), node_pressure_rate.data());
  }

  // Adds matrix_scale * sum_a (kappa_a / V_a) g_a g_a^T into the factor storage (free pairs),
  // with the rotations of the last nodal_pressure_pass.
  void assemble_nodal_volumetric(double matrix_scale) {
    double* values = cholesky.values();
    const auto& offsets = model.node_element_offsets();
    const auto& stars = model.node_elements();
    for (int a = 0; a < model.node_count(); ++a) {
      const int patch_size = patch_offsets[uz(a) + 1] - patch_offsets[uz(a)];
      patch_gradient.leftCols(patch_size).setZero();
      for (int k = offsets[uz(a)]; k < offsets[uz(a) + 1]; ++k) {
        const int e = stars[uz(k)];
        const detail::Mat34 c = (0.25 * model.element_volume_m3()[e]) * (rotations[uz(e)] * model.shape_gradients(e));
        for (int q = 0; q < 4; ++q) patch_gradient.col(star_corner_local[4 * uz(k) + uz(q)]) += c.col(q);
      }
      const double weight = matrix_scale * model.node_bulk_modulus_pa()[a] / model.node_volume_m3()[a];
      const PairSlot* slot = patch_pair_slots.data() + patch_pair_offsets[uz(a)];
      for (int i = 0; i < patch_size; ++i) {
        for (int j = i; j < patch_size; ++j, ++slot) {
          if (slot->offset < 0) continue;
          const Eigen::Vector3d gr = weight * patch_gradient.col(slot->swap != 0 ? j : i);
          const Eigen::Vector3d gc = patch_gradient.col(slot->swap != 0 ? i : j);
          double* out = values + slot->offset;
          for (int col = 0; col < 3; ++col, out += slot->ld) {
            out[0] += gr[0] * gc[col];
            out[1] += gr[1] * gc[col];
            out[2] += gr[2] * gc[col];
          }
        }
      }
    }
  }

  // One pass over the elements at positions xs: adds force_scale * (-f_int) to res, adds
  // beta_scale * K(xs) w when w != nullptr, and (if matrix_scale > 0) adds matrix_scale * K(xs)
  // into the factor storage (free-free blocks only).
  void element_pass(const double* xs, const double* wv, double beta_scale, double force_scale, double matrix_scale,
                    double* res) {
    const int m = model.element_count();
    const bool nodal = model.nodal_volumetric();
    const double mu1 = model.unit_mu();
    const double lambda1 = model.unit_element_lambda();
    double* values = cholesky.values();
    if (matrix_scale > 0) factorized = false;  // the factor's storage is being reassembled
    if (nodal) nodal_pressure_pass(xs, wv);
    for (int e = 0; e < m; ++e) {
      const auto& nodes = model.elements()[uz(e)];
      const detail::Mat34& b = model.shape_gradients(e);
      const Eigen::Matrix3d f = detail::gather_gradient(xs, nodes, b);
      const Eigen::Matrix3d r = nodal ? rotations[uz(e)] : polar_rotation(f);
      const double youngs = model.youngs_modulus_pa()[e];
      const double mu = youngs * mu1;
      const double lambda = youngs * lambda1;
      const double volume = model.element_volume_m3()[e];
      Eigen::Matrix3d p = detail::corotated_stress(f, r, mu, lambda, nullptr);
      if (nodal) p += detail::element_pressure(nodes, node_pressure.data()) * r;
      const detail::Mat34 corner = (force_scale * volume) * (p * b);
      for (int a = 0; a < 4; ++a) {
        Eigen::Map<Eigen::Vector3d>(res + 3 * nodes[uz(a)]) += corner.col(a);
      }
      if (wv == nullptr && matrix_scale <= 0) continue;
      const detail::Mat34 c = r * b;
      if (wv != nullptr) {
        detail::add_rotated_stiffness_product(c, volume, mu, lambda, wv, nodes, beta_scale, res);
        if (nodal) {
          const double rate = beta_scale * volume * detail::element_pressure(nodes, node_pressure_rate.data());
          for (int a = 0; a < 4; ++a) Eigen::Map<Eigen::Vector3d>(res + 3 * nodes[uz(a)]) += rate * c.col(a);
        }
      }
      if (matrix_scale <= 0) continue;
      const PairSlot* slots = pair_slots.data() + 10 * static_cast<std::size_t>(e);
      const double sv = matrix_scale * volume;
      const double smu = sv * mu;
      const double slambda = sv * lambda;
      for (int q = 0; q < 10; ++q) {
        const PairSlot& slot = slots[q];
        if (slot.offset < 0) continue;
        const int ia = slot.swap != 0 ? kPairB[q] : kPairA[q];
        const int ib = slot.swap != 0 ? kPairA[q] : kPairB[q];
        const Eigen::Vector3d ca = c.col(ia);
        const Eigen::Vector3d cb = c.col(ib);
        const double diag = smu * b.col(ia).dot(b.col(ib));
        double* out = values + slot.offset;
        for (int col = 0; col < 3; ++col) {
          const Eigen::Vector3d column = (slambda * cb[col]) * ca + (smu * ca[col]) * cb;
          out[0] += column[0];
          out[1] += column[1];
          out[2] += column[2];
          out[col] += diag;
          out += slot.ld;
        }
      }
    }
    if (nodal && matrix_scale > 0) assemble_nodal_volumetric(matrix_scale);
  }

  // Internal force and K(xs) v at the constrained nodes only (boundary elements), into scratch:
  // scratch = -f_int + beta K v there.
  void boundary_pass(const double* xs, const double* v, double beta) {
    for (int node : constrained) scratch.segment<3>(3 * node).setZero();
    const bool nodal = model.nodal_volumetric();
    const bool damped = v != nullptr && beta > 0;
    const double mu1 = model.unit_mu();
    const double lambda1 = model.unit_element_lambda();
    if (nodal && !boundary_elements.empty()) nodal_pressure_pass(xs, damped ? v : nullptr);
    for (int e : boundary_elements) {
      const auto& nodes = model.elements()[uz(e)];
      const detail::Mat34& b = model.shape_gradients(e);
      const Eigen::Matrix3d f = detail::gather_gradient(xs, nodes, b);
      const Eigen::Matrix3d r = nodal ? rotations[uz(e)] : polar_rotation(f);
      const double youngs = model.youngs_modulus_pa()[e];
      const double volume = model.element_volume_m3()[e];
      Eigen::Matrix3d p = detail::corotated_stress(f, r, youngs * mu1, youngs * lambda1, nullptr);
      if (nodal) p += detail::element_pressure(nodes, node_pressure.data()) * r;
      const detail::Mat34 corner = volume * (p * b);
      Eigen::Matrix<double, 3, 4> damping = Eigen::Matrix<double, 3, 4>::Zero();
      if (damped) {
        const detail::Mat34 c = r * b;
        Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
        for (int a = 0; a < 4; ++a) {
          h.noalias() += Eigen::Map<const Eigen::Vector3d>(v + 3 * nodes[uz(a)]) * c.col(a).transpose();
        }
        Eigen::Matrix3d s = youngs * mu1 * (h + h.transpose());
        s.diagonal().array() += youngs * lambda1 * h.trace();
        if (nodal) s.diagonal().array() += detail::element_pressure(nodes, node_pressure_rate.data());
        damping = (beta * volume) * (s * c);
      }
      for (int a = 0; a < 4; ++a) {
        const int node = nodes[uz(a)];
        if (free_index[uz(node)] >= 0) continue;
        scratch.segment<3>(3 * node) += corner.col(a) + damping.col(a);
      }
    }
  }

  void add_mass_diagonal(double mass_scale) {
    double* values = cholesky.values();
    for (std::size_t k = 0; k < free_nodes.size(); ++k) {
      const double value = mass_scale * model.lumped_mass_kg()[free_nodes[k]];
      double* out = values + diagonal_slot[k];
      const std::int32_t ld = diagonal_ld[k];
      out[0] += value;
      out[1 + ld] += value;
      out[2 + 2 * ld] += value;
    }
  }

  void factorize_or_throw(const char* what) {
    factorized = false;
    if (!cholesky.factorize()) {
      throw std::runtime_error(std::string("FemSolver: ") + what +
                               " matrix is not positive definite (is the body held against rigid motion?)");
    }
    factorized = true;
  }
  // Solves the factorized system for -residual on the free DOFs into rhs; returns max |dx|.
  double solve_negative_residual() {
    for (std::size_t k = 0; k < free_nodes.size(); ++k) {
      rhs.segment<3>(3 * static_cast<Eigen::Index>(k)) = -residual.segment<3>(3 * free_nodes[k]);
    }
    cholesky.solve(rhs);
    return free_nodes.empty() ? 0.0 : rhs.cwiseAbs().maxCoeff();
  }
  // Patches of the nodal formulation; adds the pairs of free patch nodes to `adjacency` (free
  // numbering). Sizes the nodal workspaces.
  void build_patches(std::vector<std::vector<int>>& adjacency) {
    const auto& offsets = model.node_element_offsets();
    const auto& stars = model.node_elements();
    const int n = model.node_count();
    patch_offsets.assign(uz(n) + 1, 0);
    star_corner_local.assign(4 * stars.size(), 0);
    std::vector<int> patch;
    int largest = 0;
    for (int a = 0; a < n; ++a) {
      patch.clear();
      for (int k = offsets[uz(a)]; k < offsets[uz(a) + 1]; ++k) {
        for (int node : model.elements()[uz(stars[uz(k)])]) patch.push_back(node);
      }
      std::sort(patch.begin(), patch.end());
      patch.erase(std::unique(patch.begin(), patch.end()), patch.end());
      for (int k = offsets[uz(a)]; k < offsets[uz(a) + 1]; ++k) {
        for (int q = 0; q < 4; ++q) {
          const int node = model.elements()[uz(stars[uz(k)])][uz(q)];
          star_corner_local[4 * uz(k) + uz(q)] =
              static_cast<int>(std::lower_bound(patch.begin(), patch.end(), node) - patch.begin());
        }
      }
      for (int i : patch) {
        const int fi = free_index[uz(i)];
        if (fi < 0) continue;
        for (int j : patch) {
          const int fj = free_index[uz(j)];
          if (fj >= 0 && fj != fi) adjacency[uz(fi)].push_back(fj);
        }
      }
      patch_nodes.insert(patch_nodes.end(), patch.begin(), patch.end());
      patch_offsets[uz(a) + 1] = static_cast<int>(patch_nodes.size());
      largest = std::max(largest, static_cast<int>(patch.size()));
    }
    patch_gradient.setZero(3, largest);
    rotations.assign(uz(model.element_count()), Eigen::Matrix3d::Identity());
    dilatation.setZero(model.element_count());
    dilatation_rate.setZero(model.element_count());
    node_pressure.setZero(n);
    node_pressure_rate.setZero(n);
  }

  // Factor slots of every free pair of every patch (after the symbolic analysis).
  void place_patch_slots() {
    const int n = model.node_count();
    patch_pair_offsets.assign(uz(n) + 1, 0);
    for (int a = 0; a < n; ++a) {
      const int begin = patch_offsets[uz(a)];
      const int size = patch_offsets[uz(a) + 1] - begin;
      for (int i = 0; i < size; ++i) {
        for (int j = i; j < size; ++j) {
          const int fi = free_index[uz(patch_nodes[uz(begin + i)])];
          const int fj = free_index[uz(patch_nodes[uz(begin + j)])];
          PairSlot out;
          if (fi >= 0 && fj >= 0) {
            const detail::BlockCholesky::Slot s = cholesky.slot(fi, fj);
            out.offset = s.offset;
            out.swap = s.row_stride != 1 ? 1 : 0;
            out.ld = static_cast<std::int32_t>(out.swap != 0 ? s.row_stride : s.col_stride);
          }
          patch_pair_slots.push_back(out);
        }
      }
      patch_pair_offsets[uz(a) + 1] = static_cast<std::int64_t>(patch_pair_slots.size());
    }
  }

  void place_constrained(Eigen::VectorXd& pos, const Eigen::VectorXd& driven_positions, const std::vector<int>& fixed,
                         const std::vector<int>& driven) const {
    for (int node : fixed) pos.segment<3>(3 * node) = model.rest_position_m().segment<3>(3 * node);
    for (std::size_t k = 0; k < driven.size(); ++k) {
      pos.segment<3>(3 * driven[k]) = driven_positions.segment<3>(3 * static_cast<Eigen::Index>(k));
    }
  }
};

FemSolver::FemSolver(const FemModel& model, std::vector<int> fixed_nodes, std::vector<int> driven_nodes)
    : model_(&model),
      fixed_(std::move(fixed_nodes)),
      driven_(std::move(driven_nodes)),
      impl_(std::make_unique<Impl>(model)) {
  const int n = model.node_count();
  std::vector<char> seen(uz(n), 0);
  check_node_list(fixed_, n, "fixed", seen);
  check_node_list(driven_, n, "driven", seen);
  Impl& im = *impl_;
  im.free_index.assign(uz(n), -1);
  for (int i = 0; i < n; ++i) {
    if (seen[uz(i)] == 0) {
      im.free_index[uz(i)] = static_cast<int>(im.free_nodes.size());
      im.free_nodes.push_back(i);
    }
  }
  im.constrained = fixed_;
  im.constrained.insert(im.constrained.end(), driven_.begin(), driven_.end());
  const int nf = static_cast<int>(im.free_nodes.size());
  std::vector<std::vector<int>> adjacency(uz(nf));
  for (int e = 0; e < model.element_count(); ++e) {
    const auto& nodes = model.elements()[uz(e)];
    bool boundary = false;
    for (int a = 0; a < 4; ++a) {
      const int fa = im.free_index[uz(nodes[uz(a)])];
      if (fa < 0) {
        boundary = true;
        continue;
      }
      for (int b = 0; b < 4; ++b) {
        const int fb = im.free_index[uz(nodes[uz(b)])];
        if (fb >= 0 && fb != fa) adjacency[uz(fa)].push_back(fb);
      }
    }
    if (boundary) im.boundary_elements.push_back(e);
  }
  if (model.nodal_volumetric()) im.build_patches(adjacency);
  for (auto& list : adjacency) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  im.cholesky.analyze(nf, adjacency);
  if (model.nodal_volumetric()) im.place_patch_slots();
  im.pair_slots.assign(10 * uz(model.element_count()), PairSlot{});
  for (int e = 0; e < model.element_count(); ++e) {
    const auto& nodes = model.elements()[uz(e)];
    for (int q = 0; q < 10; ++q) {
      const int fa = im.free_index[uz(nodes[uz(kPairA[q])])];
      const int fb = im.free_index[uz(nodes[uz(kPairB[q])])];
      if (fa < 0 || fb < 0) continue;
      const detail::BlockCholesky::Slot s = im.cholesky.slot(fa, fb);
      PairSlot& out = im.pair_slots[10 * uz(e) + uz(q)];
      out.offset = s.offset;
      out.swap = s.row_stride != 1 ? 1 : 0;
      out.ld = static_cast<std::int32_t>(out.swap != 0 ? s.row_stride : s.col_stride);
    }
  }
  for (int k = 0; k < nf; ++k) {
    const detail::BlockCholesky::Slot s = im.cholesky.slot(k, k);
    im.diagonal_slot.push_back(s.offset);
    im.diagonal_ld.push_back(static_cast<std::int32_t>(s.col_stride));
  }
  const Eigen::Map<const Eigen::Matrix3Xd> rest(model.rest_position_m().data(), 3, n);
  im.length_scale = (rest.rowwise().maxCoeff() - rest.rowwise().minCoeff()).norm();
  im.start.setZero(3 * n);
  im.x.setZero(3 * n);
  im.residual.setZero(3 * n);
  im.w.setZero(3 * n);
  im.rhs.setZero(3 * nf);
  im.reaction.setZero(3 * n);
  im.scratch.setZero(3 * n);
  im.target.setZero(3 * static_cast<Eigen::Index>(driven_.size()));
  im.previous_driven.setZero(3 * static_cast<Eigen::Index>(driven_.size()));
  im.velocity_before.setZero(3 * n);
}

void FemSolver::solve_last_factorized(Eigen::Ref<Eigen::VectorXd> vector) {
  Impl& im = *impl_;
  if (!im.factorized) throw std::logic_error("FemSolver: nothing factorized yet");
  if (vector.size() != model_->dof_count()) throw std::invalid_argument("FemSolver: vector must have 3n entries");
  for (std::size_t k = 0; k < im.free_nodes.size(); ++k) {
    im.rhs.segment<3>(3 * static_cast<Eigen::Index>(k)) = vector.segment<3>(3 * im.free_nodes[k]);
  }
  im.cholesky.solve(im.rhs);
  for (int node : im.constrained) vector.segment<3>(3 * node).setZero();
  for (std::size_t k = 0; k < im.free_nodes.size(); ++k) {
    vector.segment<3>(3 * im.free_nodes[k]) = im.rhs.segment<3>(3 * static_cast<Eigen::Index>(k));
  }
}

void FemSolver::add_tangent_product(const Eigen::Ref<const Eigen::VectorXd>& position_m,
                                    const Eigen::Ref<const Eigen::VectorXd>& u, double scale,
                                    Eigen::Ref<Eigen::VectorXd> out) {
  Impl& im = *impl_;
  const Eigen::Index dofs = model_->dof_count();
  if (position_m.size() != dofs || u.size() != dofs || out.size() != dofs) {
    throw std::invalid_argument("FemSolver: tangent product vectors must have 3n entries");
  }
  im.sensitivity.setZero(dofs);
  im.element_pass(position_m.data(), u.data(), scale, 0.0, 0.0, im.sensitivity.data());
  out += im.sensitivity;
}

void FemSolver::add_tangent_products(const Eigen::Ref<const Eigen::VectorXd>& position_m,
                                     const std::vector<const Eigen::VectorXd*>& u, const std::vector<double>& scales,
                                     const std::vector<Eigen::VectorXd*>& out, double force_scale,
                                     Eigen::VectorXd* force_out, bool rotation_derivative) {
  const FemModel& model = *model_;
  const Eigen::Index dofs = model.dof_count();
  if (u.size() != scales.size() || u.size() != out.size() || position_m.size() != dofs) {
    throw std::invalid_argument("FemSolver: tangent products need one scale and output per vector, 3n positions");
  }
  for (std::size_t k = 0; k < u.size(); ++k) {
    if (u[k]->size() != dofs || out[k]->size() != dofs) {
      throw std::invalid_argument("FemSolver: tangent product vectors must have 3n entries");
    }
  }
  if (force_out != nullptr && force_out->size() != dofs) {
    throw std::invalid_argument("FemSolver: internal force vectors must have 3n entries");
  }
  if (model.nodal_volumetric()) {  // the nodal pressure rate is per vector: one pass each
    for (std::size_t k = 0; k < u.size(); ++k) add_tangent_product(position_m, *u[k], scales[k], *out[k]);
    if (force_out != nullptr) add_internal_force(position_m, force_scale, *force_out);
    return;
  }
  const double mu1 = model.unit_mu();
  const double lambda1 = model.unit_element_lambda();
  const double* xs = position_m.data();
  for (int e = 0; e < model.element_count(); ++e) {
    const auto& nodes = model.elements()[uz(e)];
    const detail::Mat34& b = model.shape_gradients(e);
    const Eigen::Matrix3d f = detail::gather_gradient(xs, nodes, b);
    const Eigen::Matrix3d r = polar_rotation(f);
    const double youngs = model.youngs_modulus_pa()[e];
    const double mu = youngs * mu1;
    const double lambda = youngs * lambda1;
    const double volume = model.element_volume_m3()[e];
    if (force_out != nullptr) {
      const Eigen::Matrix3d p = detail::corotated_stress(f, r, mu, lambda, nullptr);
      const detail::Mat34 corner = (-force_scale * volume) * (p * b);
      for (int a = 0; a < 4; ++a) force_out->segment<3>(3 * nodes[uz(a)]) += corner.col(a);
    }
    if (rotation_derivative) {
      for (std::size_t k = 0; k < u.size(); ++k) {
        detail::add_exact_stiffness_product(f, r, b, volume, mu, lambda, u[k]->data(), nodes, scales[k],
                                            out[k]->data());
      }
      continue;
    }
    const detail::Mat34 c = r * b;
    for (std::size_t k = 0; k < u.size(); ++k) {
      detail::add_rotated_stiffness_product(c, volume, mu, lambda, u[k]->data(), nodes, scales[k], out[k]->data());
    }
  }
}

void FemSolver::add_internal_force(const Eigen::Ref<const Eigen::VectorXd>& position_m, double scale,
                                   Eigen::Ref<Eigen::VectorXd> out) {
  Impl& im = *impl_;
  const Eigen::Index dofs = model_->dof_count();
  if (position_m.size() != dofs || out.size() != dofs) {
    throw std::invalid_argument("FemSolver: internal force vectors must have 3n entries");
  }
  im.sensitivity.setZero(dofs);
  im.element_pass(position_m.data(), nullptr, 0.0, -scale, 0.0, im.sensitivity.data());
  out += im.sensitivity;
}

FemSolver::~FemSolver() = default;
FemSolver::FemSolver(FemSolver&&) noexcept = default;

int FemSolver::free_node_count() const { return static_cast<int>(impl_->free_nodes.size()); }
bool FemSolver::is_constrained(int node) const { return impl_->free_index.at(uz(node)) < 0; }
const Eigen::VectorXd& FemSolver::reaction_n() const { return impl_->reaction; }
std::size_t FemSolver::factor_entries() const { return impl_->cholesky.factor_entries(); }
int FemSolver::supernode_count() const { return impl_->cholesky.supernode_count(); }

FemState FemSolver::rest_state() const {
  FemState s;
  s.position_m = model_->rest_position_m();
  s.velocity_m_s.setZero(model_->dof_count());
  s.acceleration_m_s2.setZero(model_->dof_count());
  return s;
}

namespace {

void check_state(const FemModel& model, const FemState& state) {
  const Eigen::Index dofs = model.dof_count();
  if (state.position_m.size() != dofs || state.velocity_m_s.size() != dofs || state.acceleration_m_s2.size() != dofs) {
    throw std::invalid_argument("FemSolver: state vectors must have 3n entries");
  }
  if (!state.position_m.allFinite() || !state.velocity_m_s.allFinite() || !state.acceleration_m_s2.allFinite()) {
    throw std::invalid_argument("FemSolver: non-finite state");
  }
}

void check_forces(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& forces) {
  if (forces.size() != 0 && forces.size() != model.dof_count()) {
    throw std::invalid_argument("FemSolver: nodal forces must have 3n entries or none");
  }
  if (!forces.allFinite()) throw std::invalid_argument("FemSolver: non-finite nodal forces");
}

}  // namespace

void FemSolver::initialize_acceleration(FemState& state, const Eigen::Ref<const Eigen::VectorXd>& nodal_force_n) {
  check_state(*model_, state);
  check_forces(*model_, nodal_force_n);
  Impl& im = *impl_;
  const FemModel& model = *model_;
  // residual = -f_int + beta K v (the non-inertial left-hand side minus alpha M v).
  im.residual.setZero();
  im.element_pass(state.position_m.data(), state.velocity_m_s.data(), model.rayleigh_beta(), 1.0, 0.0,
                  im.residual.data());
  state.acceleration_m_s2.setZero();
  for (int node : im.free_nodes) {
    const double mass = model.lumped_mass_kg()[node];
    Eigen::Vector3d force = -im.residual.segment<3>(3 * node) + mass * model.gravity_m_s2() -
                            model.rayleigh_alpha() * mass * state.velocity_m_s.segment<3>(3 * node);
    if (nodal_force_n.size() != 0) force += nodal_force_n.segment<3>(3 * node);
    state.acceleration_m_s2.segment<3>(3 * node) = force / mass;
  }
  state.acceleration_valid = true;
}

FemStepReport FemSolver::step(FemState& state, double dt_s, const Eigen::Ref<const Eigen::VectorXd>& driven_position_m,
                              const Eigen::Ref<const Eigen::VectorXd>& nodal_force_n, const FemStepOptions& options) {
  const FemModel& model = *model_;
  Impl& im = *impl_;
  check_state(model, state);
  check_forces(model, nodal_force_n);
  if (!(dt_s > 0) || !std::isfinite(dt_s)) throw std::invalid_argument("FemSolver: dt must be positive and finite");
  if (options.substeps < 1 || options.newton_iterations < 1 || !(options.newton_tolerance_m >= 0)) {
    throw std::invalid_argument("FemSolver: substeps and newton_iterations must be >= 1, tolerance >= 0");
  }
  if (driven_position_m.size() != 3 * static_cast<Eigen::Index>(driven_.size())) {
    throw std::invalid_argument("FemSolver: driven positions must have 3 entries per driven node");
  }
  if (!driven_position_m.allFinite()) throw std::invalid_argument("FemSolver: non-finite driven positions");
  const bool newmark = options.integrator == FemIntegrator::newmark;
  if (newmark && !state.acceleration_valid) initialize_acceleration(state, nodal_force_n);

  for (std::size_t k = 0; k < driven_.size(); ++k) {
    im.previous_driven.segment<3>(3 * static_cast<Eigen::Index>(k)) = state.position_m.segment<3>(3 * driven_[k]);
  }
  const double h = dt_s / options.substeps;
  const double alpha = model.rayleigh_alpha();
  const double beta = model.rayleigh_beta();
  // Residual (scaled): M (dx - h v - c_a a) + D (c_d dx - c_dv v) - c_f (f_int + f_ext + M g);
  // Jacobian: (1 + c_d alpha) M + (c_d beta + c_f) K.
  const double c_a = newmark ? 0.25 * h * h : 0.0;
  const double c_d = newmark ? 0.5 * h : h;
  const double c_dv = newmark ? 0.25 * h * h : 0.0;
  const double c_f = newmark ? 0.25 * h * h : h * h;
  const Eigen::Vector3d gravity = model.gravity_m_s2();
  const bool has_force = nodal_force_n.size() != 0;
  const bool secant_driven = newmark && options.driven_velocity == FemDrivenVelocity::secant;
  FemStepReport report;
  for (int sub = 1; sub <= options.substeps; ++sub) {
    const double fraction = static_cast<double>(sub) / options.substeps;
    im.target = im.previous_driven + fraction * (driven_position_m - im.previous_driven);
    im.start = state.position_m;
    im.x = state.position_m;
    if (options.extrapolated_newton_start && state.last_substep_s > 0 && state.last_increment_m.size() == im.x.size() &&
        state.last_increment_m.allFinite()) {
      im.x += (h / state.last_substep_s) * state.last_increment_m;
    }
    im.place_constrained(im.x, im.target, fixed_, driven_);
    for (int it = 0; it < options.newton_iterations; ++it) {
      // Damping acts on w = c_f v+ (as a function of x+); driven nodes with the secant velocity.
      im.w = c_d * (im.x - im.start) - c_dv * state.velocity_m_s;
      if (secant_driven) {
        for (int node : driven_) {
          im.w.segment<3>(3 * node) = (c_f / h) * (im.x.segment<3>(3 * node) - im.start.segment<3>(3 * node));
        }
      }
      im.residual.setZero();
      im.cholesky.set_zero();
      im.element_pass(im.x.data(), beta > 0 ? im.w.data() : nullptr, beta, c_f, c_d * beta + c_f, im.residual.data());
      for (int node : im.free_nodes) {
        const Eigen::Index i = 3 * node;
        const double mass = model.lumped_mass_kg()[node];
        Eigen::Vector3d r =
            mass * ((im.x.segment<3>(i) - im.start.segment<3>(i)) - h * state.velocity_m_s.segment<3>(i) -
                    c_a * state.acceleration_m_s2.segment<3>(i) + alpha * im.w.segment<3>(i) - c_f * gravity);
        if (has_force) r -= c_f * nodal_force_n.segment<3>(i);
        im.residual.segment<3>(i) += r;
      }
      im.add_mass_diagonal(1.0 + c_d * alpha);
      im.factorize_or_throw("step");
      const double correction = im.solve_negative_residual();
      for (std::size_t k = 0; k < im.free_nodes.size(); ++k) {
        im.x.segment<3>(3 * im.free_nodes[k]) += im.rhs.segment<3>(3 * static_cast<Eigen::Index>(k));
      }
      ++report.newton_iterations;
      report.last_correction_m = correction;
      if (options.newton_tolerance_m > 0 && correction < options.newton_tolerance_m) break;
    }
    if (!im.x.allFinite()) throw std::runtime_error("FemSolver: step produced non-finite positions");
    // End-of-substep velocity and acceleration from the integrator's update formulas.
    if (secant_driven) {
      for (int node : driven_) im.velocity_before.segment<3>(3 * node) = state.velocity_m_s.segment<3>(3 * node);
    }
    if (newmark) {
      for (Eigen::Index i = 0; i < im.x.size(); ++i) {
        const double dx = im.x[i] - im.start[i];
        const double a_new = 4.0 / (h * h) * (dx - h * state.velocity_m_s[i]) - state.acceleration_m_s2[i];
        state.velocity_m_s[i] = 2.0 * dx / h - state.velocity_m_s[i];
        state.acceleration_m_s2[i] = a_new;
      }
      if (secant_driven) {
        for (int node : driven_) {
          const Eigen::Vector3d v_new = (im.x.segment<3>(3 * node) - im.start.segment<3>(3 * node)) / h;
          state.acceleration_m_s2.segment<3>(3 * node) = (v_new - im.velocity_before.segment<3>(3 * node)) / h;
          state.velocity_m_s.segment<3>(3 * node) = v_new;
        }
      }
    } else {
      for (Eigen::Index i = 0; i < im.x.size(); ++i) {
        const double v_new = (im.x[i] - im.start[i]) / h;
        state.acceleration_m_s2[i] = (v_new - state.velocity_m_s[i]) / h;
        state.velocity_m_s[i] = v_new;
      }
    }
    state.last_increment_m = im.x - im.start;
    state.last_substep_s = h;
    state.position_m = im.x;
    state.time_s += h;
    state.acceleration_valid = true;
  }
  // Reactions at the final state: r = M a + D v - f_int - f_ext - M g on constrained nodes.
  im.reaction.setZero();
  im.boundary_pass(state.position_m.data(), state.velocity_m_s.data(), beta);
  for (int node : im.constrained) {
    const Eigen::Index i = 3 * node;
    const double mass = model.lumped_mass_kg()[node];
    Eigen::Vector3d r = im.scratch.segment<3>(i) + mass * (state.acceleration_m_s2.segment<3>(i) +
                                                           alpha * state.velocity_m_s.segment<3>(i) - gravity);
    if (has_force) r -= nodal_force_n.segment<3>(i);
    im.reaction.segment<3>(i) = r;
  }
  return report;
}

FemStaticResult FemSolver::solve_static(const Eigen::Ref<const Eigen::VectorXd>& driven_position_m,
                                        const Eigen::Ref<const Eigen::VectorXd>& nodal_force_n,
                                        const FemStaticOptions& options,
                                        const Eigen::Ref<const Eigen::VectorXd>& initial_position_m) {
  const FemModel& model = *model_;
  Impl& im = *impl_;
  check_forces(model, nodal_force_n);
  if (driven_position_m.size() != 3 * static_cast<Eigen::Index>(driven_.size()) || !driven_position_m.allFinite()) {
    throw std::invalid_argument("FemSolver: driven positions must be 3 finite entries per driven node");
  }
  if (initial_position_m.size() != 0 &&
      (initial_position_m.size() != model.dof_count() || !initial_position_m.allFinite())) {
    throw std::invalid_argument("FemSolver: initial positions must be 3n finite entries or none");
  }
  if (options.max_iterations < 1 || !(options.displacement_tolerance_m >= 0) || !(options.residual_tolerance_n >= 0)) {
    throw std::invalid_argument("FemSolver: bad static options");
  }
  const double tolerance =
      options.displacement_tolerance_m > 0 ? options.displacement_tolerance_m : 1e-10 * im.length_scale;
  // External load including gravity, f_ext + M g (3n).
  Eigen::VectorXd load(model.dof_count());
  for (int i = 0; i < model.node_count(); ++i) {
    load.segment<3>(3 * i) = model.lumped_mass_kg()[i] * model.gravity_m_s2();
  }
  if (nodal_force_n.size() != 0) load += nodal_force_n;
  FemStaticResult result;
  im.x = initial_position_m.size() != 0 ? Eigen::VectorXd(initial_position_m) : model.rest_position_m();
  im.target = driven_position_m;
  im.place_constrained(im.x, im.target, fixed_, driven_);
  auto potential = [&](const Eigen::VectorXd& pos) { return elastic_energy(model, pos) - load.dot(pos); };
  auto free_residual_norm = [&]() {
    double worst = 0;
    for (int node : im.free_nodes) worst = std::max(worst, im.residual.segment<3>(3 * node).cwiseAbs().maxCoeff());
    return worst;
  };
  Eigen::VectorXd trial(model.dof_count());
  double energy = potential(im.x);
  for (int it = 0; it < options.max_iterations; ++it) {
    // residual = gradient of the potential = -(f_int + load).
    im.residual = -load;
    im.cholesky.set_zero();
    im.element_pass(im.x.data(), nullptr, 0.0, 1.0, 1.0, im.residual.data());
    result.residual_n = free_residual_norm();
    if (options.residual_tolerance_n > 0 && result.residual_n <= options.residual_tolerance_n) {
      result.converged = true;
      break;
    }
    if (im.free_nodes.empty()) {
      result.converged = true;
      break;
    }
    im.factorize_or_throw("static stiffness");
    im.solve_negative_residual();  // Newton direction d (free DOFs) in im.rhs
    double slope = 0;
    for (std::size_t k = 0; k < im.free_nodes.size(); ++k) {
      slope += im.residual.segment<3>(3 * im.free_nodes[k]).dot(im.rhs.segment<3>(3 * static_cast<Eigen::Index>(k)));
    }
    // Backtracking line search on the total potential (Armijo, c = 1e-4). The direction is a
    // descent direction because the corotational tangent is positive definite here.
    double t = 1.0;
    double trial_energy = energy;
    for (int ls = 0; ls < 40; ++ls) {
      trial = im.x;
      for (std::size_t k = 0; k < im.free_nodes.size(); ++k) {
        trial.segment<3>(3 * im.free_nodes[k]) += t * im.rhs.segment<3>(3 * static_cast<Eigen::Index>(k));
      }
      trial_energy = potential(trial);
      if (trial_energy <= energy + 1e-4 * t * slope || std::abs(trial_energy - energy) <= 1e-14 * std::abs(energy))
        break;
      t *= 0.5;
    }
    im.x = trial;
    energy = trial_energy;
    result.iterations = it + 1;
    result.last_update_m = t * (im.rhs.size() > 0 ? im.rhs.cwiseAbs().maxCoeff() : 0.0);
    if (result.last_update_m <= tolerance) {
      result.converged = true;
      break;
    }
  }
  // Final residual and reactions at the returned positions.
  im.residual = -load;
  im.element_pass(im.x.data(), nullptr, 0.0, 1.0, 0.0, im.residual.data());
  result.residual_n = free_residual_norm();
  if (!im.x.allFinite()) throw std::runtime_error("FemSolver: static solve produced non-finite positions");
  im.reaction.setZero();
  for (int node : im.constrained) im.reaction.segment<3>(3 * node) = im.residual.segment<3>(3 * node);
  result.position_m = im.x;
  result.reaction_n = im.reaction;
  return result;
}

void add_spread_force(const Eigen::Vector3d& force_n, const std::vector<int>& nodes, int node_count,
                      Eigen::VectorXd& nodal_force_n) {
  if (nodes.empty()) throw std::invalid_argument("add_spread_force: empty node set");
  if (nodal_force_n.size() == 0) nodal_force_n.setZero(3 * static_cast<Eigen::Index>(node_count));
  if (nodal_force_n.size() != 3 * static_cast<Eigen::Index>(node_count)) {
    throw std::invalid_argument("add_spread_force: force vector must have 3n entries");
  }
  const Eigen::Vector3d share = force_n / static_cast<double>(nodes.size());
  for (int node : nodes) {
    if (node < 0 || node >= node_count) throw std::invalid_argument("add_spread_force: node out of range");
    nodal_force_n.segment<3>(3 * node) += share;
  }
}

void add_spread_wrench(const Eigen::Vector3d& force_n, const Eigen::Vector3d& torque_nm, const std::vector<int>& nodes,
                       const Eigen::Ref<const Eigen::VectorXd>& position_m, Eigen::VectorXd& nodal_force_n) {
  if (nodes.empty()) throw std::invalid_argument("add_spread_wrench: empty node set");
  const Eigen::Index dofs = position_m.size();
  if (nodal_force_n.size() == 0) nodal_force_n.setZero(dofs);
  if (nodal_force_n.size() != dofs) throw std::invalid_argument("add_spread_wrench: size mismatch");
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int node : nodes) {
    if (node < 0 || 3 * static_cast<Eigen::Index>(node) >= dofs) {
      throw std::invalid_argument("add_spread_wrench: node out of range");
    }
    centroid += position_m.segment<3>(3 * node);
  }
  centroid /= static_cast<double>(nodes.size());
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();
  if (torque_nm.squaredNorm() > 0) {
    Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
    for (int node : nodes) {
      const Eigen::Vector3d r = position_m.segment<3>(3 * node) - centroid;
      j += r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose();
    }
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(j);
    omega = ldlt.solve(torque_nm);
    const Eigen::Vector3d check = j * omega - torque_nm;
    if (!omega.allFinite() || check.norm() > 1e-9 * torque_nm.norm()) {
      throw std::invalid_argument("add_spread_wrench: these nodes cannot carry the torque");
    }
  }
  const Eigen::Vector3d share = force_n / static_cast<double>(nodes.size());
  for (int node : nodes) {
    const Eigen::Vector3d r = position_m.segment<3>(3 * node) - centroid;
    nodal_force_n.segment<3>(3 * node) += share + omega.cross(r);
  }
}

Eigen::Vector3d net_force(const Eigen::Ref<const Eigen::VectorXd>& nodal_n, const std::vector<int>& nodes) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int node : nodes) {
    if (node < 0 || 3 * static_cast<Eigen::Index>(node) >= nodal_n.size())
      throw std::invalid_argument("net_force: node out of range");
    sum += nodal_n.segment<3>(3 * node);
  }
  return sum;
}

Eigen::Vector3d net_torque(const Eigen::Ref<const Eigen::VectorXd>& nodal_n, const std::vector<int>& nodes,
                           const Eigen::Ref<const Eigen::VectorXd>& position_m, const Eigen::Vector3d& point_m) {
  if (nodal_n.size() != position_m.size()) throw std::invalid_argument("net_torque: size mismatch");
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int node : nodes) {
    if (node < 0 || 3 * static_cast<Eigen::Index>(node) >= nodal_n.size())
      throw std::invalid_argument("net_torque: node out of range");
    sum += (position_m.segment<3>(3 * node) - point_m).cross(Eigen::Vector3d(nodal_n.segment<3>(3 * node)));
  }
  return sum;
}

}  // namespace pliant::host::fem
