// Products with the lower triangle of a dense symmetric matrix: in double to rounding, in single
// to about 1e-7 relative whatever the magnitudes of Q and v (both are scaled into single's range).
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

#include "linalg/dense_cholesky.hpp"
#include "linalg/symmetric_product.hpp"

using namespace contact3d;

namespace {
Eigen::MatrixXd random_symmetric(int n, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < A.size(); ++i) A.data()[i] = normal(gen);
  return A + A.transpose();
}
}  // namespace

TEST(SymmetricProduct, DoubleReadsOnlyTheLowerTriangle) {
  const Eigen::MatrixXd Q = random_symmetric(50, 1);
  Eigen::MatrixXd lower_only = Q;
  lower_only.triangularView<Eigen::StrictlyUpper>().setConstant(1e300);  // never read
  const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(50, -2.0, 3.0);
  EXPECT_LT((symmetric_product(lower_only, v) - Q * v).norm(), 1e-12 * (Q * v).norm());
  EXPECT_THROW(symmetric_product(Q, Eigen::VectorXd::Ones(49)), std::invalid_argument);
}

TEST(SymmetricProduct, BlockOfColumnsReadsOnlyTheLowerTriangle) {
  const Eigen::MatrixXd Q = random_symmetric(50, 2);
  Eigen::MatrixXd lower_only = Q;
  lower_only.triangularView<Eigen::StrictlyUpper>().setConstant(1e300);  // never read
  Eigen::MatrixXd V(50, 3);
  V << Eigen::VectorXd::LinSpaced(50, -2.0, 3.0), Eigen::VectorXd::Zero(50), Eigen::VectorXd::Constant(50, 1e-20);
  const Eigen::MatrixXd QV = symmetric_block_product(lower_only, V);
  for (int j = 0; j < 3; ++j)
    EXPECT_LE((QV.col(j) - Q * V.col(j)).norm(), 1e-12 * (Q * V.col(j)).norm()) << "column " << j;
  EXPECT_THROW(symmetric_block_product(Q, Eigen::MatrixXd::Ones(49, 2)), std::invalid_argument);
}

TEST(SymmetricProduct, SingleWithinRoundingAtAnyScale) {
  for (const double magnitude : {1e-30, 1.0, 1e30}) {
    const Eigen::MatrixXd Q = magnitude * random_symmetric(40, 3);
    const double scale = Q.norm();
    const Eigen::MatrixXf single = lower_triangle_in_single(Q, scale);
    for (const double v_magnitude : {1e-25, 1e20}) {
      const Eigen::VectorXd v = v_magnitude * Eigen::VectorXd::LinSpaced(40, -1.0, 3.0);
      const Eigen::VectorXd exact = Q * v, approx = symmetric_product(&single, scale, v);
      ASSERT_TRUE(approx.allFinite()) << magnitude << " " << v_magnitude;
      EXPECT_LT((approx - exact).norm(), 1e-6 * exact.norm()) << magnitude << " " << v_magnitude;
      EXPECT_GT((approx - exact).norm(), 0.0) << "not computed in single precision";
    }
  }
  const Eigen::MatrixXf single = lower_triangle_in_single(Eigen::MatrixXd::Identity(3, 3), 1.0);
  EXPECT_EQ(symmetric_product(&single, 1.0, Eigen::VectorXd::Zero(3)), Eigen::VectorXd::Zero(3));
  EXPECT_FALSE(symmetric_product(&single, 1.0, Eigen::Vector3d(1, std::nan(""), 0)).allFinite());
}

// Q inside a larger array (the augmented factor's root block, dense_view.hpp): columns a stride apart.
TEST(SymmetricProduct, ReadsAStridedView) {
  const Eigen::MatrixXd Q = random_symmetric(30, 5);
  Eigen::MatrixXd host = Eigen::MatrixXd::Constant(37, 34, 1e300);  // never read outside the block
  host.block(4, 3, 30, 30) = Q;
  const DenseView view = strided_view(&host(4, 3), 30, 30, host.outerStride());
  const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(30, -1.0, 2.0);
  EXPECT_LT((symmetric_product(view, v) - Q * v).norm(), 1e-12 * (Q * v).norm());
  const Eigen::MatrixXf single = lower_triangle_in_single(view, 1.0);
  EXPECT_LT((symmetric_product(&single, 1.0, v) - Q * v).norm(), 1e-5 * (Q * v).norm());
}

// One float array for a factor of Q (lower triangle) and a scaled copy S Q S of it (upper triangle,
// one column over): products through the copy and solves through the factor both stay right.
TEST(SymmetricProduct, UpperCopyBesideTheFactor) {
  const int n = 40;
  const Eigen::MatrixXd R = random_symmetric(n, 7);
  const Eigen::MatrixXd Q = R * R + n * Eigen::MatrixXd::Identity(n, n);  // positive definite
  const Eigen::VectorXd s = Q.diagonal().cwiseSqrt().cwiseInverse();
  SingleCholesky factor(lower_triangle_in_single(Q, 1.0, Eigen::VectorXd(), true));
  ASSERT_TRUE(factor.ok());
  float* spare = factor.spare_upper();
  ASSERT_NE(spare, nullptr);
  const SingleSymmetric copy = upper_triangle_in_single(Q, 2.0, s, spare, n);
  const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  const Eigen::VectorXd exact = s.asDiagonal() * (Q * (s.asDiagonal() * v));
  EXPECT_LT((symmetric_product(copy, 2.0, v) - exact).norm(), 1e-6 * exact.norm());
  EXPECT_LT((Q * factor.solve(v) - v).norm(), 1e-4 * v.norm());  // the factor is untouched
  EXPECT_EQ(SingleCholesky(lower_triangle_in_single(Q, 1.0)).spare_upper(), nullptr);
}
