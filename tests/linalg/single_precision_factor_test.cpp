// SinglePrecisionFactor's float solves against CHOLMOD's double ones.
#include "linalg/single_precision_factor.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include <Eigen/Dense>

#include "linalg/sparse_cholesky.hpp"
#include "test_support.hpp"

using namespace contact3d;
using contact3d::testing::grid_laplacian;

namespace {

double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return (a - b).norm() / b.norm(); }

}  // namespace

TEST(SinglePrecisionFactor, SolvesAsTheDoubleFactorToSinglePrecision) {
  const Eigen::SparseMatrix<double> K = grid_laplacian(16, 13, 6, 2.1e9, 6.01);  // steel-like magnitudes
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
  const Eigen::SparseMatrix<double> K = grid_laplacian(5, 4, 3);
  Eigen::SparseMatrix<double> B(2, K.rows());
  B.insert(0, 0) = 1;
  B.insert(1, 7) = 1;
  const SparseCholesky augmented(K, B);
  EXPECT_THROW(SinglePrecisionFactor{augmented}, std::logic_error);
  const SparseCholesky factor(K);
  const SinglePrecisionFactor single(factor);
  EXPECT_THROW(single.solve(Eigen::VectorXd(Eigen::VectorXd::Ones(K.rows() + 1))), std::invalid_argument);
}
