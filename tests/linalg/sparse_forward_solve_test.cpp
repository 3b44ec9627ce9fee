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

TEST(SparseForwardSolve, RefusesAnAugmentedFactorAndWrongSizes) {
  const Eigen::SparseMatrix<double> K = grid_laplacian(4, 4, 2);
  const SparseCholesky factor(K);
  const Eigen::SparseMatrix<double> wrong(K.rows() + 1, 2);
  EXPECT_THROW(forward_solve_sparse_columns(factor, wrong, 4, 1 << 20, [](int, auto, auto) {}), std::invalid_argument);
  Eigen::SparseMatrix<double> B(2, K.cols());
  B.insert(0, 0) = 1;
  B.insert(1, 5) = 1;
  const SparseCholesky augmented(K, B);
  EXPECT_THROW(forward_solve_sparse_columns(augmented, Eigen::SparseMatrix<double>(K.rows(), 1), 4, 1 << 20,
                                            [](int, auto, auto) {}),
               std::logic_error);
}
