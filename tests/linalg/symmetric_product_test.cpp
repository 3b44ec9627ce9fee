// Products with the lower triangle of a dense symmetric matrix: in double to rounding, in single
// to about 1e-7 relative whatever the magnitudes of Q and v (both are scaled into single's range).
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

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

TEST(SymmetricProduct, SingleWithinRoundingAtAnyScale) {
  for (const double magnitude : {1e-30, 1.0, 1e30}) {
    const Eigen::MatrixXd Q = magnitude * random_symmetric(40, 3);
    const double scale = Q.norm();
    const Eigen::MatrixXf single = lower_triangle_in_single(Q, scale);
    for (const double v_magnitude : {1e-25, 1e20}) {
      const Eigen::VectorXd v = v_magnitude * Eigen::VectorXd::LinSpaced(40, -1.0, 3.0);
      const Eigen::VectorXd exact = Q * v, approx = symmetric_product(single, scale, v);
      ASSERT_TRUE(approx.allFinite()) << magnitude << " " << v_magnitude;
      EXPECT_LT((approx - exact).norm(), 1e-6 * exact.norm()) << magnitude << " " << v_magnitude;
      EXPECT_GT((approx - exact).norm(), 0.0) << "not computed in single precision";
    }
  }
  const Eigen::MatrixXf single = lower_triangle_in_single(Eigen::MatrixXd::Identity(3, 3), 1.0);
  EXPECT_EQ(symmetric_product(single, 1.0, Eigen::VectorXd::Zero(3)), Eigen::VectorXd::Zero(3));
  EXPECT_FALSE(symmetric_product(single, 1.0, Eigen::Vector3d(1, std::nan(""), 0)).allFinite());
}
