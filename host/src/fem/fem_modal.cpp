// Modal analysis with Spectra (shift-and-invert Lanczos on M^-1/2 K M^-1/2).
#include "pliant/host/fem/fem_modal.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Spectra/SymEigsShiftSolver.h>

#include "fem_cholesky.hpp"
#include "fem_element.hpp"

namespace pliant::host::fem {

namespace {

std::size_t uz(int i) { return static_cast<std::size_t>(i); }

// (A - sigma I)^-1 x for A = M^-1/2 K M^-1/2 restricted to the free nodes, by the block Cholesky
// (one numeric factorization per shift; Spectra sets the shift once).
class ShiftSolve {
 public:
  using Scalar = double;
  ShiftSolve(const FemModel& model, const Eigen::VectorXd& position, const std::vector<int>& free_index, int free_count)
      : model_(model), free_index_(free_index), free_count_(free_count), stiffness_(stiffness_matrix(model, position)) {
    // The pattern of K (element pairs, and two element rings under the nodal volumetric
    // formulation) on the free nodes.
    cholesky_.analyze(free_count, detail::subset_block_pattern(stiffness_, free_index, free_count));
    scratch_.setZero(3 * free_count);
  }
  Eigen::Index rows() const { return 3 * static_cast<Eigen::Index>(free_count_); }
  Eigen::Index cols() const { return rows(); }
  void set_shift(double sigma) {
    cholesky_.set_zero();
    const Eigen::VectorXd& mass = model_.lumped_mass_kg();
    // Lower triangle of M^-1/2 K M^-1/2 on the free nodes.
    detail::add_subset_lower(stiffness_, free_index_, cholesky_,
                             [&](int row, int col) { return 1.0 / std::sqrt(mass[row] * mass[col]); });
    double* values = cholesky_.values();
    for (int i = 0; i < free_count_; ++i) {
      const detail::BlockCholesky::Slot slot = cholesky_.slot(i, i);
      for (int d = 0; d < 3; ++d) values[slot.offset + d * (slot.row_stride + slot.col_stride)] -= sigma;
    }
    if (!cholesky_.factorize()) {
      throw std::runtime_error(
          "modal_analysis: shifted stiffness is not positive definite (shift above the lowest mode?)");
    }
  }
  void perform_op(const double* x_in, double* y_out) const {
    scratch_ = Eigen::Map<const Eigen::VectorXd>(x_in, rows());
    cholesky_.solve(scratch_);
    Eigen::Map<Eigen::VectorXd>(y_out, rows()) = scratch_;
  }

 private:
  const FemModel& model_;
  const std::vector<int>& free_index_;
  int free_count_;
  Eigen::SparseMatrix<double> stiffness_;   // K at the analysed positions, all 3n DOFs
  mutable detail::BlockCholesky cholesky_;  // solve() uses internal scratch
  mutable Eigen::VectorXd scratch_;
};

}  // namespace

FemModes modal_analysis(const FemModel& model, const std::vector<int>& fixed_nodes, const FemModalOptions& options,
                        const Eigen::Ref<const Eigen::VectorXd>& position_m) {
  const int n = model.node_count();
  if (position_m.size() != 0 && (position_m.size() != model.dof_count() || !position_m.allFinite())) {
    throw std::invalid_argument("modal_analysis: positions must be 3n finite entries or none");
  }
  std::vector<int> free_index(uz(n), 0);
  for (int node : fixed_nodes) {
    if (node < 0 || node >= n) throw std::invalid_argument("modal_analysis: fixed node out of range");
    if (free_index[uz(node)] != 0) throw std::invalid_argument("modal_analysis: fixed node listed twice");
    free_index[uz(node)] = -1;
  }
  int free_count = 0;
  for (int& entry : free_index) entry = entry < 0 ? -1 : free_count++;
  const Eigen::Index free_dofs = 3 * static_cast<Eigen::Index>(free_count);
  if (options.mode_count < 1 || options.mode_count >= free_dofs) {
    throw std::invalid_argument("modal_analysis: mode_count must be in [1, free DOFs - 1]");
  }
  if (options.max_restarts < 1 || !(options.tolerance > 0)) throw std::invalid_argument("modal_analysis: bad options");
  const Eigen::VectorXd position = position_m.size() != 0 ? Eigen::VectorXd(position_m) : model.rest_position_m();
  double shift = options.shift_rad2_s2;
  if (std::isnan(shift)) {
    // A tiny negative shift: below every eigenvalue (K is positive semi-definite), so the
    // shift-and-invert ordering is the ascending one, and the shifted matrix stays definite even
    // with rigid-body modes. Scale: the mean of diag(M^-1/2 K M^-1/2).
    double trace = 0;
    for (int e = 0; e < model.element_count(); ++e) {
      const auto& b = model.shape_gradients(e);
      const double scale = model.youngs_modulus_pa()[e] * model.element_volume_m3()[e] *
                           (model.unit_lambda() + 4.0 * model.unit_mu());  // trace of each diagonal block / |b|^2
      for (int a = 0; a < 4; ++a)
        trace += scale * b.col(a).squaredNorm() / model.lumped_mass_kg()[model.elements()[uz(e)][uz(a)]];
    }
    shift = -1e-10 * trace / static_cast<double>(model.dof_count());
  }
  ShiftSolve op(model, position, free_index, free_count);
  const Eigen::Index nev = options.mode_count;
  const Eigen::Index ncv = std::min<Eigen::Index>(free_dofs, std::max<Eigen::Index>(2 * nev + 1, 20));
  Spectra::SymEigsShiftSolver<ShiftSolve> eigs(op, nev, ncv, shift);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, options.max_restarts, options.tolerance);
  if (eigs.info() != Spectra::CompInfo::Successful) {
    throw std::runtime_error("modal_analysis: Lanczos did not converge (try more restarts or a looser tolerance)");
  }
  const Eigen::VectorXd values = eigs.eigenvalues();
  const Eigen::MatrixXd vectors = eigs.eigenvectors();
  std::vector<Eigen::Index> order(static_cast<std::size_t>(values.size()));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::sort(order.begin(), order.end(), [&](Eigen::Index p, Eigen::Index q) { return values[p] < values[q]; });
  FemModes modes;
  modes.iterations = static_cast<int>(eigs.num_iterations());
  modes.omega_rad_s.resize(nev);
  modes.frequency_hz.resize(nev);
  modes.shape.setZero(3 * n, nev);
  constexpr double kTwoPi = 6.283185307179586476925;
  for (Eigen::Index m = 0; m < nev; ++m) {
    const Eigen::Index src = order[static_cast<std::size_t>(m)];
    modes.omega_rad_s[m] = std::sqrt(std::max(values[src], 0.0));
    modes.frequency_hz[m] = modes.omega_rad_s[m] / kTwoPi;
    for (int i = 0; i < n; ++i) {
      const int f = free_index[uz(i)];
      if (f < 0) continue;
      modes.shape.block<3, 1>(3 * i, m) = vectors.block<3, 1>(3 * f, src) / std::sqrt(model.lumped_mass_kg()[i]);
    }
  }
  return modes;
}

}  // namespace pliant::host::fem
