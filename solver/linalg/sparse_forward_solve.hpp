// Forward substitution L⁻¹P b for many sparse right-hand sides b (the columns of 𝔹ᵀ: a cell's
// few face dofs), each over its reach only. Entry j of L⁻¹P b can be nonzero only on the supernodes
// that hold a nonzero of P b or are ancestors of one in the elimination tree, so a block of
// neighbouring cells needs the supernodes on their paths to the root and no others — a small part
// of the factor for a cell low in the tree. Columns are solved in blocks of neighbours (ordered by
// where they enter the tree) in a compact workspace of the reach's rows (dense BLAS-3 per
// supernode: dtrsm on its diagonal block, dgemm below it), instead of n rows per column through
// every supernode.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include <Eigen/Sparse>

#include "linalg/sparse_cholesky.hpp"

namespace contact3d {

// Calls visit(j, rows, values) once for every column j of `rhs` (n × m, n = K's size) with the
// nonzero entries of L⁻¹P rhs_j: their pivot positions (rows of L) and values, in no fixed order
// (entries of the reach that come out exactly zero may be among them). Blocks hold at most
// `max_block_columns` columns and a workspace of about `block_bytes`. `factor` is a factor of K, or
// the augmented factor SparseCholesky(K, 𝔹), whose leading block is one: only that block is read
// (L₁₁⁻¹P rhs, for another 𝔹 than the one factored with K).
void forward_solve_sparse_columns(
    const SparseCholesky& factor, const Eigen::SparseMatrix<double>& rhs, int max_block_columns,
    std::int64_t block_bytes,
    const std::function<void(int column, std::span<const std::int64_t> rows, std::span<const double> values)>& visit);

// L₁₁⁻¹P rhs for all columns at once, supernode by supernode as a multifrontal solve: supernode s
// holds a dense block of its rows by exactly the columns whose reach includes it (those with an entry
// in its subtree), solved by one dtrsm and passed up to its ancestors by one dgemm — the work an
// augmented factorization does for the rows of 𝔹, where the blocks of neighbouring columns above do
// it over the union of their reaches. Same `factor` as above.
struct ForwardSolvedBlocks {
  std::int64_t rows = 0;  // K's size
  int columns = 0;        // rhs's
  // Per supernode (empty where no column reaches it): the columns that reach it, ascending, and its
  // leading rows (pivot positions first_row[s] ...) of L₁₁⁻¹P rhs by those columns, column-major.
  std::vector<std::int64_t> first_row;
  std::vector<std::vector<int>> reaching;
  std::vector<std::vector<double>> block;

  // (L₁₁⁻¹P rhs)ᵀ(L₁₁⁻¹P rhs), dense with both triangles: one dsyrk per supernode.
  Eigen::MatrixXd gram() const;
  // Its diagonal, the columns' squared norms, and its product with V (columns × k) without forming it:
  // Wᵀ(W V), two dgemm (dgemv for one vector) per supernode.
  Eigen::VectorXd column_squared_norms() const;
  Eigen::MatrixXd gram_product(const Eigen::MatrixXd& V) const;
  std::int64_t entries() const;  // stored, over all blocks
  // x −= (L₁₁⁻¹P rhs) λ, x in pivot order (K's rows first): one dgemv per supernode.
  void subtract_product(const Eigen::VectorXd& lambda, Eigen::VectorXd& x) const;
};
ForwardSolvedBlocks forward_solve_by_supernodes(const SparseCholesky& factor, const Eigen::SparseMatrix<double>& rhs);
// The entries forward_solve_by_supernodes would store (its blocks' sizes, from the columns reaching each
// supernode), without solving: what keeping them costs.
std::int64_t forward_solved_block_entries(const SparseCholesky& factor, const Eigen::SparseMatrix<double>& rhs);

}  // namespace contact3d
