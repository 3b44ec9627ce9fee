// A problem's low-rank term (BoxDiscQP::low_rank, the augmented Lagrangian's penalty AᵀA): its
// products, diagonal and reduced Newton systems equal those of a problem whose dense Q holds
// Q + AᵀA, in double and through the single copy; the semismooth Newton solver reaches the same
// answer through the bordered factor of Q alone (its Woodbury update) as on the dense Q + AᵀA; and
// the update is needed: the bordered factor without it solves another system.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

#include "linalg/dense_cholesky.hpp"
#include "linalg/symmetric_product.hpp"
#include "qp/bordered_newton.hpp"
#include "qp/newton_system.hpp"
#include "qp/ssn.hpp"
#include "test_support.hpp"

using namespace contact3d;

namespace {

using contact3d::testing::double_factor;
using contact3d::testing::make_random_qp;
using contact3d::testing::random_vector;
using contact3d::testing::RandomQp;

// A k × m penalty of rows of very different size, as √ρ Ĝ is late in the augmented Lagrangian.
Eigen::MatrixXd penalty_rows(int k, int m, unsigned seed, double size) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(k, m);
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < m; ++j) A(i, j) = normal(gen) * size / (1 + i);
  return A;
}

// The same problem twice: `penalized` with Q and the low-rank term A, `dense` with Q + AᵀA stored.
// Two of make_random_qp's point discs stay points (as in bordered_newton_test.cpp: a border of many
// would make factoring the reduced matrix the cheaper route, and the bordered factor unused).
struct TwoForms {
  RandomQp penalized, dense;
  Eigen::MatrixXd A;

  TwoForms(int r, unsigned seed, double size, double shift = 0.05)
      : penalized(make_random_qp(r, true, seed, 3, shift)), dense(make_random_qp(r, true, seed, 3, shift)) {
    int points = 0;
    for (int i = 0; i < r; ++i)
      if (penalized.qp.radius[i] == 0 && ++points > 2) penalized.qp.radius[i] = dense.qp.radius[i] = 1;
    A = penalty_rows(6, penalized.qp.size(), seed + 1, size);
    penalized.use_operator();
    penalized.qp.low_rank = A;
    penalized.qp.q_norm += A.squaredNorm();  // ‖AᵀA‖ <= ‖A‖_F²
    dense.Q += A.transpose() * A;
    dense.use_operator();
  }
  TwoForms(const TwoForms&) = delete;
};

}  // namespace

TEST(LowRankTerm, ProductsAndDiagonalTakeItIn) {
  TwoForms t(40, 3, 10.0);
  const Eigen::VectorXd v = random_vector(t.dense.qp.size(), 5);
  const Eigen::VectorXd expected = t.dense.Q * v;
  EXPECT_LT((t.penalized.qp.apply(v) - expected).norm(), 1e-12 * expected.norm());
  EXPECT_LT((t.penalized.qp.diagonal() - t.dense.Q.diagonal()).norm(), 1e-12 * t.dense.Q.diagonal().norm());
  const Eigen::MatrixXd V = Eigen::MatrixXd::Random(t.dense.qp.size(), 3);
  EXPECT_LT((t.penalized.qp.apply_block(V) - t.dense.Q * V).norm(), 1e-12 * (t.dense.Q * V).norm());
  // Through Q's single copy: Q's part to single precision, the low-rank part in double.
  const Eigen::MatrixXf q_single = lower_triangle_in_single(t.penalized.Q, 1.0);
  t.penalized.qp.Q_single = &q_single;
  const Eigen::VectorXd single = t.penalized.qp.apply_single(v);
  EXPECT_LT((single - expected).norm(), 1e-5 * expected.norm());
  EXPECT_GT((single - t.penalized.qp.apply(v)).norm(), 0);  // it did go through the copy
}

TEST(LowRankTerm, ReducedMatrixAndProductAreThoseOfTheDenseForm) {
  const TwoForms t(40, 7, 10.0);
  const Eigen::VectorXd z = random_vector(t.dense.qp.size(), 9);  // a mix of every kind of direction
  const ReducedStep step = split_active_sets(t.dense.qp, z, projection_scale(t.dense.qp));
  ASSERT_GT(step.directions.size(), 10u);
  Eigen::MatrixXd with_term, dense;
  reduced_matrix(t.penalized.qp, step.directions, with_term);
  reduced_matrix(t.dense.qp, step.directions, dense);
  // Only the lower triangles are set (the strict upper ones are left as they were: never read).
  const Eigen::MatrixXd lower = dense.triangularView<Eigen::Lower>();
  EXPECT_LT((Eigen::MatrixXd(with_term.triangularView<Eigen::Lower>()) - lower).norm(), 1e-12 * lower.norm());
  const Eigen::VectorXd y = random_vector(static_cast<Eigen::Index>(step.directions.size()), 4);
  const Eigen::VectorXd expected = reduced_product(t.dense.qp, step.directions, y);
  EXPECT_LT((reduced_product(t.penalized.qp, step.directions, y) - expected).norm(), 1e-12 * expected.norm());
}

// The penalty large against Q (‖AᵀA‖ ≈ 1e4 ‖Q‖ for its first row), as where the augmented Lagrangian
// has grown ρ: Newton steps through Q's bordered factor with the Woodbury update reach the dense
// form's answer; without the update (the term dropped from the Newton systems) they do not converge.
// The route's rounding floor is the term's size times double's: its 11 steps ended at ‖gᴾ‖/‖h‖ =
// 2.7e-11 with one BLAS thread and 2.4e-10 with two (another summation order), so the tolerance is
// 1e-9 (the answers are still compared to 1e-8).
TEST(LowRankTerm, SemismoothNewtonThroughTheBorderedFactorOfQAlone) {
  TwoForms t(200, 12, 30.0, 0.5);
  SsnSettings settings;
  settings.rtol = 1e-9;
  settings.fallback_to_mpgp = false;
  Eigen::VectorXd reference, through;
  ASSERT_EQ(solve_ssn(t.dense.qp, reference, settings).status, QpStatus::Converged);
  auto factor = make_bordered_newton(double_factor(t.penalized.Q), Eigen::VectorXd::Ones(t.penalized.qp.size()));
  ASSERT_TRUE(factor);
  t.penalized.qp.bordered = factor.get();
  const QpResult result = solve_ssn(t.penalized.qp, through, settings);
  ASSERT_EQ(result.status, QpStatus::Converged);
  EXPECT_GT(result.bordered_steps, 0);  // the route was taken
  EXPECT_LT((through - reference).norm(), 1e-8 * reference.norm());

  // The bordered factor's system without the term is another one: its step is not the Newton step.
  const ReducedStep step = split_active_sets(t.dense.qp, reference, projection_scale(t.dense.qp));
  ASSERT_TRUE(factor->prepare(step.directions));
  const Eigen::VectorXd b = random_vector(static_cast<Eigen::Index>(step.directions.size()), 2);
  Eigen::MatrixXd dense;
  reduced_matrix(t.dense.qp, step.directions, dense);
  const DenseCholesky chol(dense);
  ASSERT_TRUE(chol.ok());
  EXPECT_GT((factor->solve(b) - chol.solve(b)).norm(), 1e-3 * chol.solve(b).norm());
}
