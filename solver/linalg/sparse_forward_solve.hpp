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

#include <Eigen/Sparse>

#include "linalg/sparse_cholesky.hpp"

namespace contact3d {

// Calls visit(j, rows, values) once for every column j of `rhs` (n × m, n = K's size) with the
// nonzero entries of L⁻¹P rhs_j: their pivot positions (rows of L) and values, in no fixed order
// (entries of the reach that come out exactly zero may be among them). Blocks hold at most
// `max_block_columns` columns and a workspace of about `block_bytes`. `factor` must be the factor of
// K alone (not augmented).
void forward_solve_sparse_columns(
    const SparseCholesky& factor, const Eigen::SparseMatrix<double>& rhs, int max_block_columns,
    std::int64_t block_bytes,
    const std::function<void(int column, std::span<const std::int64_t> rows, std::span<const double> values)>& visit);

}  // namespace contact3d
