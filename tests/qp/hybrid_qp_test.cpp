// The hybrid QP solver (MPGP + semismooth Newton, the default "auto"): the same minimiser as
// MPGP on random QPs, also when every round goes through Newton steps; MPGP alone where it
// converges within its first window; and the reduced symmetric Newton step of solve_ssn on a QP
// large enough for the LAPACK path. (Its speed on slabs is measured by `make bench-slab`.)
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "linalg/dual_operator.hpp"
#include "qp/hybrid_qp.hpp"
#include "qp/mpgp.hpp"
#include "qp/ssn.hpp"
#include "test_support.hpp"

using namespace contact3d;
using contact3d::testing::make_random_qp;
using contact3d::testing::RandomQp;

namespace {

QpResult solve_reference(const BoxDiscQP& qp, Eigen::VectorXd& lambda) {
  MpgpSettings ms;
  ms.rtol = 1e-10;
  return solve_mpgp(qp, lambda, ms);
}

// One random QP solved by the hybrid with MPGP windows of `window` iterations (0: its default),
// checked against MPGP at 1e-10: converged, feasible, the same minimiser.
QpResult solve_and_compare(unsigned seed, int size, bool friction, int window) {
  RandomQp a = make_random_qp(size, friction, seed);
  a.qp.Q = &a.Q;
  a.qp.q_norm = 1.05 * estimate_norm(a.Q);
  Eigen::VectorXd reference, lambda;
  EXPECT_EQ(solve_reference(a.qp, reference).status, QpStatus::Converged) << "seed " << seed;
  HybridSettings hs;
  hs.rtol = 1e-10;
  hs.window = window;
  const QpResult r = solve_hybrid(a.qp, lambda, hs);
  EXPECT_EQ(r.status, QpStatus::Converged) << "seed " << seed;
  EXPECT_TRUE(is_feasible(a.qp, lambda)) << "seed " << seed;
  EXPECT_LT((lambda - reference).norm(), 1e-7 * (1 + reference.norm())) << "seed " << seed;
  return r;
}

}  // namespace

TEST(HybridQp, MatchesMpgpOnRandomQps) {
  for (unsigned seed = 1; seed <= 20; ++seed)
    for (bool friction : {true, false}) solve_and_compare(seed, 4 + static_cast<int>(seed) % 9, friction, 0);
}

TEST(HybridQp, NewtonRoundsHandBackToMpgp) {
  // One-iteration MPGP windows never cut ‖gᴾ‖ tenfold, so every round hands over to Newton steps
  // (which stop when they settle linearly and return without their own MPGP fallback).
  int with_newton = 0;
  for (unsigned seed = 1; seed <= 20; ++seed)
    for (bool friction : {true, false}) {
      const QpResult r = solve_and_compare(seed, 6 + static_cast<int>(seed) % 7, friction, 1);
      with_newton += r.newton_steps > 0;
      EXPECT_LE(r.newton_steps, r.iterations);
    }
  EXPECT_GE(with_newton, 30);  // of 40
}

TEST(HybridQp, MpgpAloneWhereItConvergesInItsWindow) {
  RandomQp a = make_random_qp(5, true, 3, 3, 30.0);  // well conditioned
  a.qp.Q = &a.Q;
  a.qp.q_norm = 1.05 * estimate_norm(a.Q);
  Eigen::VectorXd reference, lambda;
  const QpResult mpgp = solve_reference(a.qp, reference);
  ASSERT_EQ(mpgp.status, QpStatus::Converged);
  ASSERT_LT(mpgp.iterations, 50);  // inside the first window
  HybridSettings hs;
  hs.rtol = 1e-10;
  const QpResult r = solve_hybrid(a.qp, lambda, hs);
  EXPECT_EQ(r.newton_steps, 0);
  EXPECT_EQ(r.iterations, mpgp.iterations);
  EXPECT_LT((lambda - reference).norm(), 1e-12 * (1 + reference.norm()));
}

TEST(HybridQp, ReducedNewtonOnTheLapackPath) {  // free size >= 400: dpotrf
  RandomQp p = make_random_qp(200, true, 11);
  p.qp.Q = &p.Q;
  p.qp.q_norm = 1.05 * estimate_norm(p.Q);
  Eigen::VectorXd reference, lambda;
  ASSERT_EQ(solve_reference(p.qp, reference).status, QpStatus::Converged);
  SsnSettings ss;
  ss.rtol = 1e-10;
  const QpResult r = solve_ssn(p.qp, lambda, ss);
  ASSERT_EQ(r.status, QpStatus::Converged);
  EXPECT_GT(r.newton_steps, 0);
  EXPECT_TRUE(is_feasible(p.qp, lambda));
  EXPECT_LT((lambda - reference).norm(), 1e-6 * reference.norm());
}

TEST(HybridQp, CostlyDampedStepsCountAsSlow) {
  // A Newton step's factorization in products: k³/3 flops against 2m² per product.
  EXPECT_DOUBLE_EQ(newton_step_cost(600, 600), 100.0);
  EXPECT_DOUBLE_EQ(newton_step_cost(300, 600), 12.5);
  // With a zero budget every damped step that does not halve ‖F‖ is slow, so Newton rounds stop
  // sooner than when only full steps count (the infinite default), and never later.
  int sooner = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    RandomQp a = make_random_qp(20 + static_cast<int>(seed) % 11, true, seed);
    a.qp.Q = &a.Q;
    a.qp.q_norm = 1.05 * estimate_norm(a.Q);
    SsnSettings ss;
    ss.rtol = 1e-12;
    ss.stop_when_linear = true;
    ss.fallback_to_mpgp = false;
    Eigen::VectorXd free_lambda, budget_lambda;
    const QpResult free_run = solve_ssn(a.qp, free_lambda, ss);
    ss.damped_step_budget = 0;
    const QpResult budget_run = solve_ssn(a.qp, budget_lambda, ss);
    EXPECT_LE(budget_run.newton_steps, free_run.newton_steps) << "seed " << seed;
    EXPECT_TRUE(is_feasible(a.qp, budget_lambda)) << "seed " << seed;
    sooner += budget_run.newton_steps < free_run.newton_steps;
  }
  EXPECT_GE(sooner, 1);
}
