// Newton steps without Q's entries (qp/reduced_cg.hpp, the matrix-free dual's Newton steps): CG on
// the reduced system gives what a dense factorization of it gives, from zero or from a start, and
// stops at its product budget; semismooth Newton and the hybrid on a matrix-free QP (Q only as a
// product) reach MPGP's minimiser.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "linalg/dual_operator.hpp"
#include "qp/hybrid_qp.hpp"
#include "qp/mpgp.hpp"
#include "qp/newton_system.hpp"
#include "qp/reduced_cg.hpp"
#include "qp/ssn.hpp"
#include "test_support.hpp"

using namespace contact3d;
using contact3d::testing::make_random_qp;
using contact3d::testing::RandomQp;

namespace {

// `a`'s QP as a matrix-free one: the same Q, seen only through products and its diagonal.
BoxDiscQP matrix_free_copy(const RandomQp& a) {
  BoxDiscQP qp = a.qp;
  qp.Q = nullptr;
  const Eigen::MatrixXd* Q = &a.Q;
  qp.product = [Q](const Eigen::VectorXd& v) { return Eigen::VectorXd(*Q * v); };
  qp.q_diagonal = a.Q.diagonal();
  qp.q_norm = 1.05 * estimate_norm(a.Q);
  return qp;
}

}  // namespace

TEST(ReducedCg, SolvesTheReducedSystemAsItsFactorizationDoes) {
  int sliding = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    RandomQp a = make_random_qp(12, true, seed);
    a.qp.Q = &a.Q;
    const BoxDiscQP free = matrix_free_copy(a);
    // Active sets of some z: normals in and out of contact, tangents inside and outside their discs.
    const Eigen::VectorXd z = 1.5 * a.qp.h / a.Q.diagonal().mean();
    const double rho = projection_scale(a.qp);
    const ReducedStep step = split_active_sets(a.qp, z, rho);
    for (const Direction& d : step.directions) sliding += d.b >= 0;
    ASSERT_FALSE(step.directions.empty());
    const Eigen::VectorXd b = restrict_to(step.directions, a.qp.h - a.Q * step.lambda_fixed);
    Eigen::MatrixXd A;
    reduced_matrix(a.qp, step.directions, A);
    const Eigen::VectorXd exact = A.selfadjointView<Eigen::Lower>().llt().solve(b);

    Eigen::VectorXd y;  // from zero
    const ReducedCgResult cg = solve_reduced_cg(free, step.directions, b, 1e-12 * b.norm(), 1000, y);
    EXPECT_TRUE(cg.converged) << "seed " << seed;
    EXPECT_LE(cg.iterations, 2 * static_cast<int>(b.size())) << "seed " << seed;
    EXPECT_LT((y - exact).norm(), 1e-9 * exact.norm()) << "seed " << seed;

    Eigen::VectorXd from_solution = exact;  // a start at the solution costs its one residual product
    const ReducedCgResult warm = solve_reduced_cg(free, step.directions, b, 1e-8 * b.norm(), 1000, from_solution);
    EXPECT_TRUE(warm.converged);
    EXPECT_EQ(warm.iterations, 1);

    Eigen::VectorXd capped;  // the budget is a hard stop, reported as not converged
    const ReducedCgResult short_run = solve_reduced_cg(free, step.directions, b, 1e-14 * b.norm(), 2, capped);
    EXPECT_FALSE(short_run.converged);
    EXPECT_EQ(short_run.iterations, 2);
    EXPECT_LT((capped - exact).norm(), exact.norm());  // CG's iterates approach the solution in A's norm
  }
  EXPECT_GT(sliding, 0);  // the two-weight (sliding) directions were exercised
}

TEST(ReducedCg, NewtonOnAMatrixFreeQpReachesMpgpsMinimiser) {
  int newton_steps = 0;
  for (unsigned seed = 1; seed <= 12; ++seed)
    for (bool friction : {true, false}) {
      RandomQp a = make_random_qp(6 + static_cast<int>(seed) % 9, friction, seed);
      a.qp.Q = &a.Q;
      a.qp.q_norm = 1.05 * estimate_norm(a.Q);
      Eigen::VectorXd reference;
      MpgpSettings ms;
      ms.rtol = 1e-10;
      ASSERT_EQ(solve_mpgp(a.qp, reference, ms).status, QpStatus::Converged);
      const BoxDiscQP free = matrix_free_copy(a);

      Eigen::VectorXd by_ssn;
      SsnSettings ss;
      ss.rtol = 1e-10;
      const QpResult rs = solve_ssn(free, by_ssn, ss);
      EXPECT_EQ(rs.status, QpStatus::Converged) << "seed " << seed;
      EXPECT_TRUE(is_feasible(free, by_ssn));
      EXPECT_LT((by_ssn - reference).norm(), 1e-7 * (1 + reference.norm())) << "seed " << seed;
      newton_steps += rs.newton_steps;

      Eigen::VectorXd by_hybrid;
      HybridSettings hs;
      hs.rtol = 1e-10;
      hs.window = 1;  // every round hands over to Newton steps (no cap on rounds without Q's entries)
      const QpResult rh = solve_hybrid(free, by_hybrid, hs);
      EXPECT_EQ(rh.status, QpStatus::Converged) << "seed " << seed;
      EXPECT_LT((by_hybrid - reference).norm(), 1e-7 * (1 + reference.norm())) << "seed " << seed;
    }
  EXPECT_GT(newton_steps, 0);
}
