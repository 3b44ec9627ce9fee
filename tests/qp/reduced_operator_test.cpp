// ReducedOperator (newton_system.hpp): once it keeps Dᵀ Q D + diag(shift) in double (few directions
// beside m), its products are those computed through Q, for a Jacobi-scaled problem with a low-rank
// term and every kind of direction; before keep(), or where it does not keep them (many directions,
// or a matrix-free Q), it goes through Q itself.
#include <gtest/gtest.h>

#include <vector>

#include <Eigen/Dense>

#include "qp/jacobi_scaling.hpp"
#include "qp/newton_system.hpp"
#include "test_support.hpp"

using namespace contact3d;

namespace {

using contact3d::testing::make_random_qp;
using contact3d::testing::matrix_free_copy;
using contact3d::testing::random_vector;
using contact3d::testing::RandomQp;

// Every kind of direction (normal, inside a disc, sliding with its shift) from a random z.
std::vector<Direction> mixed_directions(const BoxDiscQP& qp, unsigned seed) {
  const ReducedStep step = split_active_sets(qp, random_vector(qp.size(), seed), projection_scale(qp));
  return step.directions;
}

bool has_shifted_pair(const std::vector<Direction>& d) {
  for (const Direction& x : d)
    if (x.b >= 0 && x.shift != 0) return true;
  return false;
}

}  // namespace

TEST(ReducedOperator, KeptEntriesGiveTheProductsThroughQ) {
  RandomQp rq = make_random_qp(60, true, 21);
  rq.use_operator();
  rq.qp.low_rank = Eigen::MatrixXd::Random(3, rq.qp.size());
  JacobiScaledQP jacobi(rq.qp);
  const BoxDiscQP& qp = jacobi.scaled(rq.qp.radius);
  std::vector<Direction> d = mixed_directions(qp, 4);
  ASSERT_TRUE(has_shifted_pair(d));
  d.resize(static_cast<std::size_t>(qp.size() / 3));  // k <= m / 2: kept
  ReducedOperator A;
  const auto k = static_cast<Eigen::Index>(d.size());
  const Eigen::VectorXd y = random_vector(k, 5);
  const Eigen::VectorXd through_Q = reduced_product(qp, d, y);
  EXPECT_FALSE(A.kept());  // through Q until asked
  EXPECT_EQ(A.product(qp, d, y), through_Q);
  A.keep(qp, d);
  ASSERT_TRUE(A.kept());
  EXPECT_LT((A.product(qp, d, y) - through_Q).norm(), 1e-12 * through_Q.norm());
  const Eigen::MatrixXd Y = Eigen::MatrixXd::Random(k, 4);
  const Eigen::MatrixXd block_through_Q = reduced_block_product(qp, d, Y);
  EXPECT_LT((A.block_product(qp, d, Y) - block_through_Q).norm(), 1e-12 * block_through_Q.norm());
}

TEST(ReducedOperator, ManyDirectionsOrAMatrixFreeQGoThroughQ) {
  RandomQp rq = make_random_qp(60, true, 22);
  rq.use_operator();
  const std::vector<Direction> all = mixed_directions(rq.qp, 6);
  ASSERT_GT(2 * all.size(), static_cast<std::size_t>(rq.qp.size()));  // more than m / 2
  ReducedOperator many;
  many.keep(rq.qp, all);
  EXPECT_FALSE(many.kept());
  const Eigen::VectorXd y = random_vector(static_cast<Eigen::Index>(all.size()), 7);
  EXPECT_EQ(many.product(rq.qp, all, y), reduced_product(rq.qp, all, y));

  const BoxDiscQP matrix_free = matrix_free_copy(rq);
  std::vector<Direction> few = all;
  few.resize(10);
  ReducedOperator on_matrix_free;
  on_matrix_free.keep(matrix_free, few);
  EXPECT_FALSE(on_matrix_free.kept());
}
