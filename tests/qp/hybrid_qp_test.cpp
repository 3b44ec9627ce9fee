// The hybrid QP solver (MPGP + semismooth Newton, the default "auto"): the same minimiser as
// MPGP on random QPs, also when every round goes through Newton steps; MPGP alone where it
// converges within its first window; and the reduced symmetric Newton step of solve_ssn on a QP
// large enough for the LAPACK path; when a Newton round ends (SlowNewtonSteps); further rounds only
// while they converge (NewtonRoundGate); its heartbeat counts the whole solve. (Its speed on slabs
// is measured by `make bench-slab`.)
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

// Q of rank deficiency 100 shifted by 1e-7 (cond about 1e10), m = 400, h made so that `solution` is
// the minimiser with a quarter of the multipliers degenerate (λ_i = 0 with a zero gradient), solved by
// the hybrid from zero at `rtol`, one-iteration MPGP windows, at most 3 000 iterations.
struct DegenerateSolve {
  QpResult result;
  Eigen::VectorXd lambda, solution;
  bool feasible = false;
};
DegenerateSolve solve_degenerate_ill_conditioned(unsigned seed, double rtol, Progress* progress = nullptr) {
  constexpr int m = 400;
  RandomQp a = make_random_qp(m, false, seed, -100, 1e-7);
  DegenerateSolve out;
  out.solution.resize(m);
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(m);
  for (int i = 0; i < m; ++i) {
    out.solution[i] = i % 4 < 2 ? 1.0 + 0.1 * (i % 3) : 0.0;
    if (i % 4 == 2) gradient[i] = 0.5;
  }
  a.qp.h = a.Q * out.solution - gradient;
  a.use_operator();
  HybridSettings hs;
  hs.rtol = rtol;
  hs.window = 1;
  hs.max_iterations = 3000;
  hs.progress = progress;
  out.result = solve_hybrid(a.qp, out.lambda, hs);
  out.feasible = is_feasible(a.qp, out.lambda);
  return out;
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

TEST(HybridQp, NewtonRoundsEndWhereStepsStopPaying) {
  // A Newton step's factorization in products: k³/3 flops against 2m² per product.
  EXPECT_DOUBLE_EQ(newton_step_cost(600, 600), 100.0);
  EXPECT_DOUBLE_EQ(newton_step_cost(300, 600), 12.5);
  const double budget = 50, costly = 100, cheap = 10;
  {  // two full steps in a row that do not halve ‖F‖, whatever they cost
    SlowNewtonSteps s{budget};
    EXPECT_FALSE(s.record(1, 1.0, 0.8, cheap));
    EXPECT_TRUE(s.record(1, 0.8, 0.7, cheap));
  }
  {  // a step that halves ‖F‖ resets the count
    SlowNewtonSteps s{budget};
    EXPECT_FALSE(s.record(1, 1.0, 0.8, cheap));
    EXPECT_FALSE(s.record(1, 0.8, 0.1, cheap));
    EXPECT_FALSE(s.record(1, 0.1, 0.09, cheap));
  }
  {  // damped steps before any full step: globalization, never slow
    SlowNewtonSteps s{budget};
    for (int k = 0; k < 5; ++k) EXPECT_FALSE(s.record(0.25, 1.0, 0.9, costly)) << k;
  }
  {  // after a full step, costly damped steps that creep end the round; cheap ones go on
    SlowNewtonSteps creeping{budget}, cheap_steps{budget};
    EXPECT_FALSE(creeping.record(1, 1.0, 1e-3, costly));
    EXPECT_FALSE(creeping.record(0.5, 1e-3, 8e-4, costly));
    EXPECT_TRUE(creeping.record(0.5, 8e-4, 7e-4, costly));
    EXPECT_FALSE(cheap_steps.record(1, 1.0, 1e-3, cheap));
    for (int k = 0; k < 5; ++k) EXPECT_FALSE(cheap_steps.record(0.5, 1e-3, 9e-4, cheap)) << k;
  }
}

// MPGP's windows: m/256 iterations on a large dense Q (a Newton step factors a system that grows with
// m), the floor of 25 on a matrix-free one (a Newton step is CG products) and on small problems.
TEST(HybridQp, WindowsGrowWithADenseQOnly) {
  const Eigen::MatrixXd stand_in = Eigen::MatrixXd::Identity(1, 1);  // only Q's presence matters here
  BoxDiscQP dense;
  dense.Q = &stand_in;
  dense.r = 4000;  // 12 000 multipliers
  EXPECT_EQ(default_window(dense), 12000 / 256);
  BoxDiscQP matrix_free = dense;
  matrix_free.Q = nullptr;
  EXPECT_EQ(default_window(matrix_free), kMinWindow);
  BoxDiscQP small = dense;
  small.r = 1000;  // 3 000 multipliers: 3000 / 256 = 11
  EXPECT_EQ(default_window(small), kMinWindow);
}

TEST(HybridQp, NewtonRoundsBeyondTheFreeOnesOnlyWhileTheyConverge) {
  NewtonRoundGate gate{2};
  EXPECT_TRUE(gate.admit(1e-3));
  EXPECT_TRUE(gate.admit(5e-3));   // the free rounds, whatever ‖gᴾ‖ did
  EXPECT_TRUE(gate.admit(1e-4));   // below the round before: the alternation converges
  EXPECT_FALSE(gate.admit(1e-4));  // no lower: MPGP windows and Newton rounds would only alternate
  EXPECT_TRUE(gate.admit(1e-6));
  EXPECT_FALSE(gate.admit(2e-6));
  NewtonRoundGate none{0};
  EXPECT_TRUE(none.admit(1.0));
  EXPECT_FALSE(none.admit(std::nan("")));
}

TEST(HybridQp, IllConditionedQpToATightToleranceTakesFurtherNewtonRounds) {
  // solve_degenerate_ill_conditioned at rtol 1e-12 (what the equality loop of a body held by contact
  // alone asks): its degenerate multipliers Newton settles a few at a time. With at most three Newton rounds, MPGP
  // alone crawled after them: 2 of these 6 stopped at 3 000 iterations, ‖gᴾ‖ 3e-12 and 2e-9.
  // Further rounds, each starting lower, finish all six.
  int converged = 0;
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const DegenerateSolve d = solve_degenerate_ill_conditioned(seed, 1e-12);
    converged += d.result.status == QpStatus::Converged;
    EXPECT_LT((d.lambda - d.solution).norm(), 1e-10 * d.solution.norm()) << "seed " << seed;
    EXPECT_TRUE(d.feasible) << "seed " << seed;
  }
  EXPECT_EQ(converged, 6);
}

TEST(HybridQp, RoundingFloorIsTwoNewtonRoundsEndingAtTheSameLevelNearTheTarget) {
  RoundingFloor floor;
  EXPECT_FALSE(floor.reached(1.04e-12, 1e-12));  // one round: nothing to compare with
  EXPECT_TRUE(floor.reached(1.03e-12, 1e-12));   // the next one no lower: the floor
  RoundingFloor converging;
  EXPECT_FALSE(converging.reached(8e-12, 1e-12));
  EXPECT_FALSE(converging.reached(3e-12, 1e-12));  // each round lower: not a floor
  EXPECT_FALSE(converging.reached(1.5e-12, 1e-12));
  RoundingFloor far_above;
  EXPECT_FALSE(far_above.reached(1e-9, 1e-12));
  EXPECT_FALSE(far_above.reached(1e-9, 1e-12));  // stalled, but far from the target: not accepted
}

TEST(HybridQp, RoundingFloorIsEightWindowsNearTheTargetThatGainLessThanATenth) {
  RoundingFloor floor;
  EXPECT_FALSE(floor.reached_by_windows(9.3e-13, 1e-13));  // the first window near the target
  for (int k = 1; k < RoundingFloor::kStalledWindows; ++k)
    EXPECT_FALSE(floor.reached_by_windows(k % 2 ? 1e-12 : 8.5e-13, 1e-13)) << k;  // noise, less than a tenth lower
  EXPECT_TRUE(floor.reached_by_windows(9.9e-13, 1e-13));
  RoundingFloor creeping;  // 8% lower each window: a tenth within two windows, never a floor
  double pg = 9e-13;
  for (int k = 0; k < 40; ++k, pg *= 0.92) EXPECT_FALSE(creeping.reached_by_windows(pg, 1e-13)) << k;
  RoundingFloor far_above;  // stalled, but more than ten times the target: not accepted
  for (int k = 0; k < 40; ++k) EXPECT_FALSE(far_above.reached_by_windows(1.1e-12, 1e-13)) << k;
  RoundingFloor interrupted;  // a window far above the target starts the count again
  for (int k = 0; k < RoundingFloor::kStalledWindows - 1; ++k) interrupted.reached_by_windows(9e-13, 1e-13);
  EXPECT_FALSE(interrupted.reached_by_windows(5e-11, 1e-13));
  EXPECT_FALSE(interrupted.reached_by_windows(9e-13, 1e-13));
}

TEST(HybridQp, ATargetBelowRoundingStopsAtTheFloorWithTheSameMinimiser) {
  // The QP of the test above asked 1e-16, below what its products and Newton systems resolve:
  // MPGP's windows would wait for a dip of the noise; the hybrid stops where two Newton rounds end
  // at the same level (within ten times the target) and says so in rounding_stops.
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const DegenerateSolve d = solve_degenerate_ill_conditioned(seed, 1e-16);
    EXPECT_EQ(d.result.status, QpStatus::Converged) << "seed " << seed;
    EXPECT_EQ(d.result.rounding_stops, 1) << "seed " << seed;
    EXPECT_LE(d.result.projected_gradient, RoundingFloor::kRoundingSlack * 1e-16) << "seed " << seed;
    EXPECT_LT((d.lambda - d.solution).norm(), 1e-13 * d.solution.norm()) << "seed " << seed;
    EXPECT_TRUE(d.feasible) << "seed " << seed;
  }
}

TEST(HybridQp, HeartbeatCountsTheWholeSolve) {
  // The heartbeat of a hybrid solve counts the work of every MPGP window and Newton round before it:
  // each window's line restarted at its own count ("iteration 0, 1 products" 13 s into a solve).
  std::vector<std::string> lines;
  Progress progress([](const std::string&) {}, [&](const std::string& line) { lines.push_back(line); }, 0.0);
  const QpResult r = solve_degenerate_ill_conditioned(3, 1e-16, &progress).result;
  std::vector<int> iterations, products;
  bool newton_line = false;
  for (const std::string& line : lines) {
    int it = 0, prod = 0;
    ASSERT_EQ(std::sscanf(line.c_str() + line.find("iteration"), "iteration %d, %d products", &it, &prod), 2) << line;
    iterations.push_back(it);
    products.push_back(prod);
    newton_line = newton_line || line.find("qp (ssn)") != std::string::npos;
  }
  ASSERT_GE(lines.size(), 3u);
  EXPECT_TRUE(newton_line);
  EXPECT_TRUE(std::is_sorted(iterations.begin(), iterations.end()));
  EXPECT_TRUE(std::is_sorted(products.begin(), products.end()));
  EXPECT_LE(iterations.back(), r.iterations);
  EXPECT_LE(products.back(), r.hessian_products);
  EXPECT_GE(iterations.back(), r.iterations / 2);  // the lines come throughout the solve
  EXPECT_GE(products.back(), r.hessian_products / 2);
}
