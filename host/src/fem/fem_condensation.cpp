#include "pliant/host/fem/fem_condensation.hpp"

#include <Eigen/SparseCore>

#include <stdexcept>
#include <string>

#include "fem_cholesky.hpp"

namespace pliant::host::fem {
namespace {

std::size_t uz(int i) { return static_cast<std::size_t>(i); }

// -1 for probed and clamped nodes, else the node's index among the relaxed ones. Validates.
std::vector<int> relaxed_index(int node_count, const std::vector<int>& probed, const std::vector<int>& clamped,
                               int& relaxed_count) {
  std::vector<int> index(uz(node_count), 0);
  auto mark = [&](const std::vector<int>& nodes, const char* what) {
    for (int node : nodes) {
      if (node < 0 || node >= node_count) {
        throw std::invalid_argument(std::string("condensed_stiffness: ") + what + " node " + std::to_string(node) +
                                    " out of range");
      }
      if (index[uz(node)] != 0) {
        throw std::invalid_argument("condensed_stiffness: node " + std::to_string(node) +
                                    " listed twice (probed and clamped must be disjoint, without repeats)");
      }
      index[uz(node)] = -1;
    }
  };
  mark(probed, "probed");
  mark(clamped, "clamped");
  relaxed_count = 0;
  for (int& entry : index) entry = entry == 0 ? relaxed_count++ : -1;
  return index;
}

}  // namespace

Eigen::MatrixXd condensed_stiffness(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& position_m,
                                    const std::vector<int>& probed, const std::vector<int>& clamped,
                                    double stiffness_coefficient, double mass_coefficient) {
  if (!(stiffness_coefficient >= 0) || !(mass_coefficient >= 0)) {
    throw std::invalid_argument("condensed_stiffness: coefficients must be >= 0");
  }
  const int n = model.node_count();
  int relaxed_count = 0;
  const std::vector<int> index = relaxed_index(n, probed, clamped, relaxed_count);

  Eigen::SparseMatrix<double> a = stiffness_coefficient * stiffness_matrix(model, position_m);
  if (mass_coefficient > 0) {
    for (int node = 0; node < n; ++node) {
      for (int k = 0; k < 3; ++k)
        a.coeffRef(3 * node + k, 3 * node + k) += mass_coefficient * model.lumped_mass_kg()(node);
    }
  }

  detail::BlockCholesky cholesky;
  if (relaxed_count > 0) {
    cholesky.analyze(relaxed_count, detail::subset_block_pattern(a, index, relaxed_count));
    cholesky.set_zero();
    detail::add_subset_lower(a, index, cholesky, [](int, int) { return 1.0; });
    if (!cholesky.factorize()) {
      throw std::runtime_error("condensed_stiffness: the relaxed nodes are not held against rigid motion");
    }
  }

  const Eigen::Index p = 3 * static_cast<Eigen::Index>(probed.size());
  Eigen::MatrixXd condensed(p, p);
  Eigen::VectorXd rhs(3 * static_cast<Eigen::Index>(relaxed_count));
  Eigen::VectorXd relaxed_motion = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(n));
  for (Eigen::Index c = 0; c < p; ++c) {
    const int column = 3 * probed[uz(static_cast<int>(c / 3))] + static_cast<int>(c % 3);
    // A unit motion of probed DOF c: the relaxed nodes answer with y = -A_ff^-1 A_fc.
    rhs.setZero();
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, column); it; ++it) {
      const int fa = index[uz(static_cast<int>(it.row()) / 3)];
      if (fa >= 0) rhs(3 * fa + static_cast<int>(it.row()) % 3) = -it.value();
    }
    if (relaxed_count > 0) cholesky.solve(rhs);
    relaxed_motion.setZero();
    for (int node = 0; node < n; ++node) {
      if (index[uz(node)] >= 0) relaxed_motion.segment<3>(3 * node) = rhs.segment<3>(3 * index[uz(node)]);
    }
    relaxed_motion(column) = 1.0;
    const Eigen::VectorXd holding = a * relaxed_motion;
    for (Eigen::Index r = 0; r < p; ++r) {
      condensed(r, c) = holding(3 * probed[uz(static_cast<int>(r / 3))] + static_cast<int>(r % 3));
    }
  }
  return 0.5 * (condensed + condensed.transpose());
}

}  // namespace pliant::host::fem
