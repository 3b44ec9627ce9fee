// SinglePrecisionFactor's float solves against CHOLMOD's double ones.
#include "linalg/single_precision_factor.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include <Eigen/Dense>

#include "linalg/sparse_cholesky.hpp"

using namespace contact3d;

namespace {

// A shifted 7-point Laplacian on an nx × ny × nz grid, times `stiffness` (steel-like magnitudes:
// K's entries near 1e9), with many supernodes under nested dissection.
Eigen::SparseMatrix<double> scaled_grid_laplacian(int nx, int ny, int nz, double stiffness) {
  const int n = nx * ny * nz;
  auto id = [&](int i, int j, int k) { return (k * ny + j) * nx + i; };
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int p = id(i, j, k);
        t.emplace_back(p, p, 6.01 * stiffness);
        if (i + 1 < nx) t.emplace_back(p, id(i + 1, j, k), -stiffness), t.emplace_back(id(i + 1, j, k), p, -stiffness);
        if (j + 1 < ny) t.emplace_back(p, id(i, j + 1, k), -stiffness), t.emplace_back(id(i, j + 1, k), p, -stiffness);
        if (k + 1 < nz) t.emplace_back(p, id(i, j, k + 1), -stiffness), t.emplace_back(id(i, j, k + 1), p, -stiffness);
      }
  Eigen::SparseMatrix<double> K(n, n);
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return (a - b).norm() / b.norm(); }

}  // namespace

TEST(SinglePrecisionFactor, SolvesAsTheDoubleFactorToSinglePrecision) {
  const Eigen::SparseMatrix<double> K = scaled_grid_laplacian(16, 13, 6, 2.1e9);
  const SparseCholesky factor(K);
  const SinglePrecisionFactor single(factor);
  EXPECT_EQ(single.size(), K.rows());
  EXPECT_DOUBLE_EQ(SinglePrecisionFactor::bytes_for(factor), 4.0 * (factor.supernodes().px[factor.supernodes().count]));

  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd B(K.rows(), 5);
  for (Eigen::Index i = 0; i < B.size(); ++i) B.data()[i] = normal(rng);
  B.col(1) *= 1e-25;  // tiny loads: scaled into float's range, not flushed to zero
  B.col(2) *= 1e25;
  B.col(3).setZero();
  const Eigen::MatrixXd exact = factor.solve(B);

  for (int c = 0; c < B.cols(); ++c) {
    const Eigen::VectorXd x = single.solve(Eigen::VectorXd(B.col(c)));
    if (c == 3) {
      EXPECT_EQ(x.norm(), 0.0);
      continue;
    }
    const double error = relative_difference(x, exact.col(c));
    EXPECT_LT(error, 1e-5) << "column " << c;
    EXPECT_GT(error, 1e-12) << "column " << c << ": not computed in single precision";
    // The residual in double: what the float solve leaves of the load.
    EXPECT_LT((K * x - B.col(c)).norm() / B.col(c).norm(), 1e-4) << "column " << c;
  }
  // Several right-hand sides at once (strsm/sgemm) give the column solves' result.
  const Eigen::MatrixXd blocked = single.solve(B);
  for (int c = 0; c < B.cols(); ++c) {
    const Eigen::VectorXd one = single.solve(Eigen::VectorXd(B.col(c)));
    if (c == 3) {
      EXPECT_EQ(blocked.col(c).norm(), 0.0);
      continue;
    }
    EXPECT_LT(relative_difference(blocked.col(c), one), 1e-5) << "column " << c;
    EXPECT_LT(relative_difference(blocked.col(c), exact.col(c)), 1e-5) << "column " << c;
  }
}

TEST(SinglePrecisionFactor, RefusesAnAugmentedFactorAndWrongSizes) {
  const Eigen::SparseMatrix<double> K = scaled_grid_laplacian(5, 4, 3, 1.0);
  Eigen::SparseMatrix<double> B(2, K.rows());
  B.insert(0, 0) = 1;
  B.insert(1, 7) = 1;
  const SparseCholesky augmented(K, B);
  EXPECT_THROW(SinglePrecisionFactor{augmented}, std::logic_error);
  const SparseCholesky factor(K);
  const SinglePrecisionFactor single(factor);
  EXPECT_THROW(single.solve(Eigen::VectorXd(Eigen::VectorXd::Ones(K.rows() + 1))), std::invalid_argument);
}
