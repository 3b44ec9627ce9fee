// forward_solve_sparse_columns against CHOLMOD's dense forward solve L⁻¹P B.
#include "linalg/sparse_forward_solve.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include <Eigen/Dense>

#include "linalg/sparse_cholesky.hpp"
#include "test_support.hpp"

using namespace contact3d;
using contact3d::testing::grid_laplacian;

namespace {

// Columns with a few nonzeros each on the grid's bottom layer (as a cell's face dofs), one empty.
Eigen::SparseMatrix<double> face_columns(int nx, int ny, int nz, int m) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> pick(0, nx * ny - 1);
  std::uniform_real_distribution<double> value(0.1, 1.0);
  std::vector<Eigen::Triplet<double>> t;
  for (int c = 0; c < m; ++c) {
    if (c == m / 2) continue;  // an empty column
    for (int e = 0; e < 4; ++e) t.emplace_back(pick(rng), c, value(rng));
  }
  Eigen::SparseMatrix<double> B(nx * ny * nz, m);
  B.setFromTriplets(t.begin(), t.end());
  return B;
}

}  // namespace

TEST(SparseForwardSolve, EqualsTheDenseForwardSolveInAnyBlocking) {
  const int nx = 14, ny = 12, nz = 5, m = 60;
  const SparseCholesky factor(grid_laplacian(nx, ny, nz));
  const Eigen::SparseMatrix<double> B = face_columns(nx, ny, nz, m);
  const Eigen::MatrixXd dense = factor.forward_solve(Eigen::MatrixXd(B));
  // One column per block, a few, all at once, and a workspace budget that cuts blocks short.
  for (const auto& [columns, bytes] :
       std::vector<std::pair<int, std::int64_t>>{{1, 1LL << 30}, {7, 1LL << 30}, {m, 1LL << 30}, {m, 4096}}) {
    Eigen::MatrixXd sparse = Eigen::MatrixXd::Zero(dense.rows(), m);
    std::vector<int> visits(m, 0);
    forward_solve_sparse_columns(factor, B, columns, bytes,
                                 [&](int j, std::span<const std::int64_t> rows, std::span<const double> values) {
                                   ASSERT_EQ(rows.size(), values.size());
                                   ++visits[j];
                                   for (std::size_t k = 0; k < rows.size(); ++k) sparse(rows[k], j) += values[k];
                                 });
    for (int j = 0; j < m; ++j) EXPECT_EQ(visits[j], 1) << "column " << j;
    EXPECT_LT((sparse - dense).norm(), 1e-12 * dense.norm()) << columns << " columns per block";
    EXPECT_EQ(sparse.col(m / 2).norm(), 0.0);
  }
}

// A column low in the tree reaches only part of the factor: the entries it gets are far fewer than n.
TEST(SparseForwardSolve, AColumnGetsOnlyItsReach) {
  const int nx = 30, ny = 30, nz = 3;
  const SparseCholesky factor(grid_laplacian(nx, ny, nz));
  Eigen::SparseMatrix<double> b(nx * ny * nz, 1);
  b.insert(0, 0) = 1.0;  // a grid corner
  std::size_t entries = 0;
  forward_solve_sparse_columns(
      factor, b, 1, 1LL << 30,
      [&](int, std::span<const std::int64_t> rows, std::span<const double>) { entries = rows.size(); });
  EXPECT_GT(entries, 0u);
  EXPECT_LT(entries, static_cast<std::size_t>(nx * ny * nz) / 4);
}

// An augmented factor [K 𝔹ᵀ; 𝔹 0] (multipliers last) is read over its leading block, a factor of K:
// the same L⁻¹P B as K's own factor gives (both order K's dofs by the same nested dissection).
TEST(SparseForwardSolve, ReadsTheLeadingBlockOfAnAugmentedFactor) {
  const int nx = 10, ny = 9, nz = 4, m = 30;
  const Eigen::SparseMatrix<double> K = grid_laplacian(nx, ny, nz);
  const SparseCholesky plain(K);
  const Eigen::SparseMatrix<double> first = face_columns(nx, ny, nz, 12);
  const SparseCholesky augmented(K, Eigen::SparseMatrix<double>(first.transpose()));
  const Eigen::SparseMatrix<double> B = face_columns(nx, ny, nz, m);
  const Eigen::MatrixXd dense = plain.forward_solve(Eigen::MatrixXd(B));
  Eigen::MatrixXd sparse = Eigen::MatrixXd::Zero(dense.rows(), m);
  forward_solve_sparse_columns(augmented, B, 8, 1LL << 30,
                               [&](int j, std::span<const std::int64_t> rows, std::span<const double> values) {
                                 for (std::size_t k = 0; k < rows.size(); ++k) {
                                   ASSERT_LT(rows[k], K.rows());  // never a multiplier's row
                                   sparse(rows[k], j) += values[k];
                                 }
                               });
  // Column norms are order-free: ‖L⁻¹P b‖² = bᵀK⁻¹b whatever the pivot order.
  for (int j = 0; j < m; ++j)
    EXPECT_NEAR(sparse.col(j).squaredNorm(), dense.col(j).squaredNorm(), 1e-12 * dense.col(j).squaredNorm() + 1e-300);
  EXPECT_LT((sparse.transpose() * sparse - dense.transpose() * dense).norm(),
            1e-12 * (dense.transpose() * dense).norm());
}

// All columns at once, supernode by supernode, on a factor of K and on the leading block of an
// augmented one: WᵀW = 𝔹K⁻¹𝔹ᵀ (𝔹ᵀ = rhs) and W λ against the dense forward solve, the empty column
// included.
TEST(SparseForwardSolve, BySupernodesGivesTheGramAndProductsOfTheDenseSolve) {
  const int nx = 11, ny = 9, nz = 4, m = 40;
  const Eigen::SparseMatrix<double> K = grid_laplacian(nx, ny, nz);
  const Eigen::SparseMatrix<double> B = face_columns(nx, ny, nz, m);
  const SparseCholesky plain(K);
  const Eigen::MatrixXd dense = plain.forward_solve(Eigen::MatrixXd(B));
  const Eigen::MatrixXd gram = dense.transpose() * dense;
  const SparseCholesky augmented(K, Eigen::SparseMatrix<double>(face_columns(nx, ny, nz, 12).transpose()));
  for (const SparseCholesky* factor : {&plain, &augmented}) {
    const ForwardSolvedBlocks W = forward_solve_by_supernodes(*factor, B);
    EXPECT_EQ(W.rows, K.rows());
    EXPECT_EQ(W.columns, m);
    const Eigen::MatrixXd Q = W.gram();
    EXPECT_LT((Q - gram).norm(), 1e-12 * gram.norm());
    EXPECT_EQ(Q.row(m / 2).norm(), 0.0);
    // W λ, then its norm against the dense one (pivot orders may differ: compare ‖Wλ‖² = λᵀQλ).
    Eigen::VectorXd lambda = Eigen::VectorXd::LinSpaced(m, -1.0, 2.0);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(factor->factored_size());
    W.subtract_product(lambda, x);
    EXPECT_NEAR(x.squaredNorm(), (dense * lambda).squaredNorm(), 1e-12 * (dense * lambda).squaredNorm());
    EXPECT_EQ(x.tail(factor->factored_size() - K.rows()).norm(), 0.0);  // never a multiplier's row
    EXPECT_THROW(W.subtract_product(Eigen::VectorXd::Zero(m + 1), x), std::invalid_argument);
  }
}

TEST(SparseForwardSolve, RefusesWrongSizes) {
  const Eigen::SparseMatrix<double> K = grid_laplacian(4, 4, 2);
  const SparseCholesky factor(K);
  const Eigen::SparseMatrix<double> wrong(K.rows() + 1, 2);
  EXPECT_THROW(forward_solve_sparse_columns(factor, wrong, 4, 1 << 20, [](int, auto, auto) {}), std::invalid_argument);
  EXPECT_THROW(forward_solve_by_supernodes(factor, wrong), std::invalid_argument);
}
