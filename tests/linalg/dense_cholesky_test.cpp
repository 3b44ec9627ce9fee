// DenseCholesky: both paths (Eigen below 400 rows, LAPACK above) solve SPD systems to rounding
// and report a matrix that is not positive definite.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

#include "linalg/dense_cholesky.hpp"

using namespace contact3d;

namespace {
Eigen::MatrixXd random_spd(int n, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(n + 2, n);
  for (int i = 0; i < A.rows(); ++i)
    for (int j = 0; j < n; ++j) A(i, j) = normal(gen);
  return A.transpose() * A + 0.1 * Eigen::MatrixXd::Identity(n, n);
}
// A random orthogonal basis times λ_k = 10^(−decades k / (n − 1)): a known spectrum (returned in
// `eig`) graded like a dual operator's.
Eigen::MatrixXd graded_spectrum_matrix(int n, unsigned seed, double decades, Eigen::VectorXd& eig) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(random_spd(n, seed));
  const Eigen::MatrixXd V = qr.householderQ();
  eig.resize(n);
  for (int k = 0; k < n; ++k) eig[k] = std::pow(10.0, -decades * k / (n - 1));
  return V * eig.asDiagonal() * V.transpose();
}
}  // namespace

TEST(DenseCholesky, SolvesOnBothPaths) {
  for (int n : {1, 37, 399, 400, 650}) {
    const Eigen::MatrixXd A = random_spd(n, static_cast<unsigned>(n));
    const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
    const DenseCholesky chol(A);
    ASSERT_TRUE(chol.ok()) << n;
    const Eigen::VectorXd y = chol.solve(A * x);
    EXPECT_LT((y - x).norm(), 1e-8 * x.norm()) << n;
    EXPECT_EQ(chol.pivots().size(), n);
    EXPECT_GT(chol.pivots().minCoeff(), 0.0);
  }
}

TEST(DenseCholesky, ReportsIndefiniteMatrices) {
  for (int n : {5, 450}) {
    Eigen::MatrixXd A = random_spd(n, 3);
    A(n / 2, n / 2) = -1.0;  // no longer positive definite
    EXPECT_FALSE(DenseCholesky(A).ok()) << n;
  }
  EXPECT_TRUE(DenseCholesky(Eigen::MatrixXd(0, 0)).ok());
}

// The smallest eigenvalue from subspace iteration on A⁻¹ (cond(Q) of the stability check): never
// below the true one, and within 1% of it on matrices whose smallest eigenvalues are graded like a
// dual operator's (here λ_k = 10^(−6 k / n)), on both solve paths; the block solve matches the
// single one.
TEST(DenseCholesky, SmallestEigenvalueFromAbove) {
  for (int n : {60, 500}) {
    Eigen::VectorXd eig;
    const Eigen::MatrixXd A = graded_spectrum_matrix(n, 11, 6, eig);
    const DenseCholesky chol(A);
    ASSERT_TRUE(chol.ok()) << n;
    const double estimate = smallest_eigenvalue(chol, A), exact = eig.minCoeff();
    EXPECT_GE(estimate, exact * (1 - 1e-9)) << n;
    EXPECT_LT(estimate, 1.01 * exact) << n;
    const Eigen::MatrixXd B = A.leftCols(3);
    const Eigen::MatrixXd X = chol.solve_columns(B);
    for (int j = 0; j < 3; ++j) EXPECT_LT((X.col(j) - chol.solve(Eigen::VectorXd(B.col(j)))).norm(), 1e-10) << n;
  }
}

// λmin from a single-precision factor: the subspace iteration runs on single's A⁻¹, the
// Rayleigh–Ritz values use A in double, so the estimate is as close as the double factor's and
// still from above (cond(A) = 1e4, where single keeps about three digits of A⁻¹). "As close": within
// 1e-8 of λmin beyond the double factor's error (n = 60: 1.15e-9 on this machine's OpenBLAS kernels, the
// double factor's 1e-13; single's own digits would leave about 1e-4).
TEST(SingleCholesky, SmallestEigenvalueAsCloseAsInDouble) {
  for (int n : {60, 500}) {
    Eigen::VectorXd eig;
    const Eigen::MatrixXd A = graded_spectrum_matrix(n, 12, 4, eig);
    const SingleCholesky single(A.cast<float>());
    ASSERT_TRUE(single.ok()) << n;
    EXPECT_NEAR(single.pivots().maxCoeff(), DenseCholesky(A).pivots().maxCoeff(), 1e-5 * A.diagonal().maxCoeff());
    const double estimate = smallest_eigenvalue(single, A), exact = eig.minCoeff();
    const double in_double = smallest_eigenvalue(DenseCholesky(A), A);
    EXPECT_GE(estimate, exact * (1 - 1e-9)) << n;
    EXPECT_LT(estimate - exact, 2 * (in_double - exact) + 1e-8 * exact) << n;
    const Eigen::MatrixXd B = A.leftCols(3) * 1e-20;
    const Eigen::MatrixXd X = single.solve_columns(B);
    for (int j = 0; j < 3; ++j) {
      EXPECT_LT((X.col(j) - single.solve(Eigen::VectorXd(B.col(j)))).norm(), 5e-3 * X.col(j).norm()) << n;
      EXPECT_LT((A * X.col(j) - B.col(j)).norm(), 1e-2 * B.col(j).norm()) << n;
    }
  }
}

// The single-precision factorization: solves to single's rounding (the caller refines), reports a
// matrix that is not positive definite, and passes zero and non-finite right-hand sides through.
TEST(SingleCholesky, SolvesToSinglePrecision) {
  for (int n : {30, 450}) {
    const Eigen::MatrixXd A = random_spd(n, 5);
    const SingleCholesky chol(A.cast<float>());
    ASSERT_TRUE(chol.ok()) << n;
    const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, -1e30, 2e30);
    const Eigen::VectorXd y = chol.solve(A * x);
    EXPECT_LT((y - x).norm(), 1e-2 * x.norm()) << n;
    EXPECT_GT((y - x).norm(), 1e-12 * x.norm()) << "not computed in single precision";
    EXPECT_TRUE(chol.solve(Eigen::VectorXd::Zero(n)).isZero(0));
  }
  Eigen::MatrixXd B = random_spd(20, 3);
  B(4, 4) = -1;
  EXPECT_FALSE(SingleCholesky(B.cast<float>()).ok());
}
