// Supernodal sparse Cholesky for symmetric positive definite matrices made of 3x3 node blocks
// (private to the host library). The FEM solvers refactorize the same pattern every step, so the
// symbolic work (fill-reducing ordering on the node graph, elimination tree, supernodes, update
// maps) is done once, and each numeric factorization is dense kernels (Eigen LLT, TRSM, SYRK)
// on supernode panels plus precomputed scatters. Values are assembled straight into the factor
// storage through block slots, so there is no intermediate sparse matrix.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace pliant::host::fem::detail {

class BlockCholesky {
 public:
  /// Where the lower-triangle copy of block (i, j) lives: entry (r, c) of A's block (i, j) is
  /// values()[offset + r * row_stride + c * col_stride].
  struct Slot {
    std::ptrdiff_t offset = 0;
    std::ptrdiff_t row_stride = 1;
    std::ptrdiff_t col_stride = 1;
  };

  /// Symbolic analysis of a matrix with `node_count` 3x3 block rows. adjacency[i] lists the nodes
  /// j whose block (i, j) may be non-zero (symmetric; i itself may be omitted). Allocates every
  /// buffer the numeric phase needs.
  void analyze(int node_count, const std::vector<std::vector<int>>& adjacency);

  int node_count() const { return node_count_; }
  /// Slot of block (i, j), original node numbering; (i, j) must be in the analysed pattern or
  /// i == j. Both (i, j) and (j, i) name the same storage, transposed.
  Slot slot(int i, int j) const;
  void set_zero();
  double* values() { return values_.data(); }

  /// In-place numeric factorization of the assembled values. False if the matrix is not
  /// positive definite to working precision (a pivot <= 1e-13 times its original diagonal
  /// entry); the factor is then unusable until the next assembly.
  bool factorize();
  /// Solves A x = b in place (3 * node_count entries, original numbering).
  void solve(Eigen::Ref<Eigen::VectorXd> rhs);

  /// Entries of the factor (for reports and benchmarks).
  std::size_t factor_entries() const { return values_.size(); }
  int supernode_count() const { return static_cast<int>(super_first_.size()) - 1; }

 private:
  struct Target {  // one ancestor supernode receiving part of a supernode's update
    int supernode = 0;
    int begin = 0;       // first below-row (index into the source's below rows) in its columns
    int end = 0;         // one past the last
    int map_offset = 0;  // into target_rows_: positions in the target's rows for below-rows begin..
  };

  int node_count_ = 0;
  std::vector<int> perm_;     // perm_[new] = old
  std::vector<int> inverse_;  // inverse_[old] = new
  std::vector<int> node_super_;
  std::vector<int> super_first_;              // first node (new numbering) of each supernode, plus end
  std::vector<int> super_rows_begin_;         // into rows_, per supernode plus end
  std::vector<int> rows_;                     // row nodes (new numbering) of each supernode, sorted
  std::vector<std::ptrdiff_t> super_values_;  // offset of each panel in values_
  std::vector<int> super_targets_begin_;
  std::vector<Target> targets_;
  std::vector<int> target_rows_;
  std::vector<double> values_;
  std::vector<double> update_;
  Eigen::VectorXd permuted_;
  Eigen::VectorXd diagonal_;
  Eigen::VectorXd gather_;
};

/// The block pattern of a node-major sparse matrix `a` (3x3 blocks) restricted to a subset of
/// its nodes: index[node] is the node's row in the subset, or -1 when it is left out.
/// adjacency[i] lists the other subset nodes block row i touches, sorted, for analyze().
std::vector<std::vector<int>> subset_block_pattern(const Eigen::SparseMatrix<double>& a, const std::vector<int>& index,
                                                   int subset_count);

/// Adds the lower triangle of `a` restricted to the subset (index as above) into the factor's
/// block slots, each entry times scale(node_row, node_col) (original node numbers). The factor
/// must have been analysed with subset_block_pattern(a, index, ...) or a wider pattern.
template <typename Scale>
void add_subset_lower(const Eigen::SparseMatrix<double>& a, const std::vector<int>& index, BlockCholesky& cholesky,
                      Scale&& scale) {
  double* values = cholesky.values();
  for (int col = 0; col < a.outerSize(); ++col) {
    const int node_col = col / 3;
    const int fq = index[static_cast<std::size_t>(node_col)];
    if (fq < 0) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, col); it; ++it) {
      const int node_row = static_cast<int>(it.row()) / 3;
      const int fa = index[static_cast<std::size_t>(node_row)];
      if (fa < fq) continue;  // the slot of (fa, fq) with fa >= fq holds both triangles' blocks
      const BlockCholesky::Slot slot = cholesky.slot(fa, fq);
      const int i = static_cast<int>(it.row()) % 3;
      const int j = col % 3;
      values[slot.offset + i * slot.row_stride + j * slot.col_stride] += it.value() * scale(node_row, node_col);
    }
  }
}

}  // namespace pliant::host::fem::detail
