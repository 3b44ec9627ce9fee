// Joint Newton steps on (λ, μ) for the dual QP with equality constraints (qp/equality_newton.hpp):
// from the QP's own solution at μ = 0 they must reach a λ that meets Gλ = e and solves the QP
// without equalities for the linear term h − Gᵀδμ (checked by an independent MPGP solve), and
// report failure, not a wrong answer, where the loads cannot be balanced.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

#include "qp/equality_newton.hpp"
#include "qp/mpgp.hpp"
#include "test_support.hpp"

using namespace contact3d;

namespace {

struct EqualityCase {
  contact3d::testing::RandomQp rq;
  Eigen::MatrixXd G;
  Eigen::VectorXd e;
};

// Two rows: a "lift" whose normal entries push, and a random one; e met by a strictly feasible point.
EqualityCase make_case(unsigned seed) {
  std::mt19937 gen(100 + seed);
  std::normal_distribution<double> normal;
  EqualityCase c{contact3d::testing::make_random_qp(10, true, seed), {}, {}};
  c.rq.use_operator();
  const int m = c.rq.qp.size();
  c.G.resize(2, m);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < m; ++j) c.G(i, j) = normal(gen);
  c.G.row(0).head(c.rq.qp.r).array() = c.G.row(0).head(c.rq.qp.r).array().abs() + 0.5;
  Eigen::VectorXd feasible = Eigen::VectorXd::Zero(m);
  feasible.head(c.rq.qp.r).setConstant(1.0);
  c.e = c.G * feasible;
  return c;
}

Eigen::VectorXd mpgp_solution(const BoxDiscQP& qp) {
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(qp.size());
  MpgpSettings mpgp;
  mpgp.rtol = 1e-12;
  EXPECT_EQ(solve_mpgp(qp, lambda, mpgp).status, QpStatus::Converged);
  return lambda;
}

}  // namespace

TEST(EqualityNewton, BalancesTheLoadsWithLambdaSolvingItsQp) {
  int converged = 0;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    EqualityCase c = make_case(seed);
    EqualityNewtonSettings settings;
    settings.rtol = 1e-10;
    settings.balance_target = 1e-9 * c.e.norm();
    const EqualityNewtonResult result =
        solve_equality_newton(c.rq.qp, c.G, c.e, Eigen::MatrixXd::Identity(2, 2), mpgp_solution(c.rq.qp), settings);
    ASSERT_TRUE(result.converged) << "seed " << seed;
    ++converged;
    EXPECT_EQ(result.work.status, QpStatus::Converged);
    EXPECT_GT(result.work.newton_steps, 0) << "seed " << seed;  // the start does not balance the loads
    EXPECT_TRUE(is_feasible(c.rq.qp, result.lambda));
    EXPECT_LE((c.G * result.lambda - c.e).norm(), settings.balance_target) << "seed " << seed;
    BoxDiscQP shifted = c.rq.qp;
    shifted.h = c.rq.qp.h - c.G.transpose() * result.mu_shift;
    const Eigen::VectorXd independent = mpgp_solution(shifted);
    EXPECT_LT((result.lambda - independent).norm(), 1e-7 * independent.norm()) << "seed " << seed;
  }
  EXPECT_EQ(converged, 8);
}

// Only the kept conditions are driven to zero: with C the first row alone, the second row's loads
// stay as they fall.
TEST(EqualityNewton, MeetsOnlyTheKeptConditions) {
  EqualityCase c = make_case(3);
  EqualityNewtonSettings settings;
  settings.rtol = 1e-10;
  settings.balance_target = 1e-9 * c.e.norm();
  const Eigen::MatrixXd first = Eigen::Vector2d(1, 0);
  const EqualityNewtonResult result = solve_equality_newton(c.rq.qp, c.G, c.e, first, mpgp_solution(c.rq.qp), settings);
  ASSERT_TRUE(result.converged);
  EXPECT_LE(std::abs(c.G.row(0).dot(result.lambda) - c.e[0]), settings.balance_target);
  EXPECT_EQ(result.mu_shift[1], 0.0);  // δμ stays in the range of C
}

// Loads the constraint set cannot balance (the lift pulls the body down: every normal entry of the
// row positive, e negative): no convergence is claimed, and no best iterate is handed over (every
// step leaves the loads as unbalanced as the start: the caller keeps its own iterate).
TEST(EqualityNewton, UnbalancedLoadsAreNotReportedAsConverged) {
  EqualityCase c = make_case(5);
  c.e[0] = -1e6;
  EqualityNewtonSettings settings;
  settings.rtol = 1e-10;
  settings.balance_target = 1e-9;
  const EqualityNewtonResult result =
      solve_equality_newton(c.rq.qp, c.G, c.e, Eigen::MatrixXd::Identity(2, 2), mpgp_solution(c.rq.qp), settings);
  EXPECT_FALSE(result.converged);
  EXPECT_GT(result.work.newton_steps, 0);
  EXPECT_FALSE(result.improved);
}

// A tolerance below rounding (nothing can meet rtol = 1e-20 with the balance exactly zero): once the
// active sets settle, a step solves the same linear system again, so the steps are given up after a
// few that do not halve the merit — not after twenty, each a new least value by rounding (a pressed
// plate held by contact alone spent 1 587 products so, kMaxSettledStepsWithoutProgress). Given up,
// they hand over their least-merit iterate (`improved`): it balances the loads and solves the QP for
// its shifted linear term, so the caller's steps on μ go on from there instead of from the start (a
// free plate with 13 467 multipliers whose active sets flipped at its zone's edge: 812 s → 33 s).
TEST(EqualityNewton, GivesUpSoonOnceTheActiveSetsSettleAtRoundingAndHandsOverItsBest) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    EqualityCase c = make_case(seed);
    EqualityNewtonSettings settings;
    settings.rtol = 1e-20;
    settings.balance_target = 0;
    const Eigen::VectorXd start = mpgp_solution(c.rq.qp);
    const EqualityNewtonResult result =
        solve_equality_newton(c.rq.qp, c.G, c.e, Eigen::MatrixXd::Identity(2, 2), start, settings);
    EXPECT_FALSE(result.converged) << "seed " << seed;
    EXPECT_GT(result.work.newton_steps, 1) << "seed " << seed;
    EXPECT_LE(result.work.newton_steps, 10) << "seed " << seed;
    ASSERT_TRUE(result.improved) << "seed " << seed;
    EXPECT_TRUE(is_feasible(c.rq.qp, result.lambda));
    EXPECT_LT((c.G * result.lambda - c.e).norm(), 1e-8 * (c.G * start - c.e).norm()) << "seed " << seed;
    BoxDiscQP shifted = c.rq.qp;
    shifted.h = c.rq.qp.h - c.G.transpose() * result.mu_shift;
    const Eigen::VectorXd independent = mpgp_solution(shifted);
    EXPECT_LT((result.lambda - independent).norm(), 1e-7 * independent.norm()) << "seed " << seed;
  }
}
