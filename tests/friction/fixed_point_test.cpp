// The fixed point's named exits on synthetic maps G (no contact problem behind them): it
// converges on a contraction, hits the iteration limit on a slow one, reports the inner solver's
// failure, tightens the inner tolerance before it ever calls noise "stagnation", and declares
// stagnation only for a map that does not contract. The contraction factor and the a posteriori
// bound are checked against the known rate.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "friction/fixed_point.hpp"

namespace contact3d {
namespace {

// G(φ) = φ* + q (φ − φ*) (+ noise of size noise·rtol that a tighter tolerance removes).
SlipMap linear_map(double q, double noise_per_rtol = 0) {
  return [=, flip = 0](const Eigen::VectorXd& phi, double rtol) mutable {
    const Eigen::VectorXd star = Eigen::VectorXd::LinSpaced(phi.size(), 1.0, 2.0);
    SlipEvaluation e;
    e.slip = star + q * (phi - star);
    flip = 1 - flip;
    e.slip += (flip ? 1.0 : -1.0) * noise_per_rtol * rtol * Eigen::VectorXd::Ones(phi.size());
    e.qp_iterations = 1;
    e.hessian_products = 2;
    return e;
  };
}

FixedPointSettings settings(FixedPointVariant v = FixedPointVariant::Plain) {
  FixedPointSettings s;
  s.variant = v;
  return s;
}

// How many steps' inputs were made by `update` (history.csv's `update` column).
int steps_made_by(const FixedPointResult& r, FixedPointUpdate update) {
  return static_cast<int>(
      std::count_if(r.history.begin(), r.history.end(), [&](const FixedPointStep& s) { return s.update == update; }));
}

TEST(FixedPoint, ConvergesOnAContractionWithTheRateItObserves) {
  const FixedPointResult r = solve_fixed_point(linear_map(0.3), 5, settings(), 1e-6);
  EXPECT_EQ(r.status, FixedPointStatus::Converged);
  EXPECT_NEAR(r.contraction_factor, 0.3, 1e-6);
  EXPECT_LE(r.distance_bound, 0.3 / 0.7 * r.history.back().err * (1 + 1e-9));
  EXPECT_TRUE(r.hint.empty());
  // err(k) of the plain iteration from 0 falls by q per step after the first.
  for (std::size_t k = 2; k < r.history.size(); ++k) EXPECT_LT(r.history[k].err, 0.5 * r.history[k - 1].err);
}

// A QP blind at tolerances looser than `sees`: warm-started from the last answer, it stops at once (no
// iteration) and G(φ) is that answer again — err ≈ 0 at any distance from the fixed point, as on a thin
// strip whose Q has cond ≈ 1e9. At `sees` and tighter it solves: G(φ) = φ* + q (φ − φ*).
SlipMap blind_above(double sees, double q) {
  return [=, last = Eigen::VectorXd()](const Eigen::VectorXd& phi, double rtol) mutable {
    SlipEvaluation e;
    if (last.size() && rtol > sees) {
      e.slip = last;
      e.qp_iterations = 0;
      return e;
    }
    const Eigen::VectorXd star = Eigen::VectorXd::LinSpaced(phi.size(), 1.0, 2.0);
    e.slip = last = star + q * (phi - star);
    e.qp_iterations = 10;
    e.hessian_products = 12;
    return e;
  };
}

// A step whose QP did not move cannot show convergence: it is repeated at the final step's tolerance,
// and once a repeat finds the looser tolerance blind, the run keeps the final one. Taking the idle
// step for convergence (within 100x of the final tolerance, as before), the run stopped 2.5e-3 from
// the fixed point with tol = 1e-4.
TEST(FixedPoint, AStepWhoseQpDidNotMoveIsNoConvergence) {
  FixedPointSettings s = settings(FixedPointVariant::Plain);
  const double final_rtol = final_step_qp_rtol(s, 1e-6);
  const FixedPointResult r = solve_fixed_point(blind_above(final_rtol, 0.5), 4, s, 1e-6);
  ASSERT_EQ(r.status, FixedPointStatus::Converged);
  const Eigen::VectorXd star = Eigen::VectorXd::LinSpaced(4, 1.0, 2.0);
  EXPECT_LT((r.phi - star).norm() / star.norm(), 3 * s.tol);
  EXPECT_GE(r.qp_tolerance_tightenings, 1);
  EXPECT_GT(r.history.back().qp_iterations, 0);
}

TEST(FixedPoint, IterationLimitOnASlowContractionSaysWhatToTry) {
  FixedPointSettings s = settings();
  s.max_iterations = 10;
  const FixedPointResult r = solve_fixed_point(linear_map(0.95), 4, s, 1e-6);
  EXPECT_EQ(r.status, FixedPointStatus::IterationLimit);
  EXPECT_EQ(r.iterations(), 10);
  EXPECT_NEAR(r.contraction_factor, 0.95, 1e-6);
  EXPECT_NE(r.hint.find("fixed_point_max_iter"), std::string::npos);
}

TEST(FixedPoint, IterationLimitBeforeARateIsObservedSaysSoWithoutANaN) {
  FixedPointSettings s = settings();
  s.max_iterations = 2;
  const FixedPointResult r = solve_fixed_point(linear_map(0.5), 4, s, 1e-6);
  EXPECT_EQ(r.status, FixedPointStatus::IterationLimit);
  EXPECT_TRUE(std::isnan(r.contraction_factor));
  EXPECT_NE(r.hint.find("fixed_point_max_iter"), std::string::npos);
  EXPECT_EQ(r.hint.find("nan"), std::string::npos) << r.hint;
}

TEST(FixedPoint, AcceleratedBeatsPlainOnASlowSteadyContraction) {
  // q = 0.8: the secant ω = 1/(1 − q) = 5 is capped at 4, i.e. a rate of 1 − 4·0.2 = 0.2 per step.
  const FixedPointResult plain = solve_fixed_point(linear_map(0.8), 4, settings(), 1e-6);
  const FixedPointResult fast = solve_fixed_point(linear_map(0.8), 4, settings(FixedPointVariant::Accelerated), 1e-6);
  EXPECT_EQ(plain.status, FixedPointStatus::Converged);
  EXPECT_EQ(fast.status, FixedPointStatus::Converged);
  EXPECT_LT(fast.iterations(), plain.iterations() / 3);
}

TEST(FixedPoint, AcceleratedKeepsThePlainStepsWhenTheMapContractsFast) {
  const FixedPointResult plain = solve_fixed_point(linear_map(0.2), 4, settings(), 1e-6);
  const FixedPointResult fast = solve_fixed_point(linear_map(0.2), 4, settings(FixedPointVariant::Accelerated), 1e-6);
  ASSERT_EQ(fast.iterations(), plain.iterations());
  for (int k = 0; k < plain.iterations(); ++k) EXPECT_DOUBLE_EQ(fast.history[k].err, plain.history[k].err);
}

TEST(FixedPoint, AcceleratedLeavesAContractionJustUnderHalfThatHasFarToGo) {
  // q = 0.45: each step is under half the one before, but from err ≈ 0.2 the paper's steps would
  // need about ten more to reach tol (the puck with a jump law: 14 plain steps). The accelerated
  // variant hands over once more than four would remain.
  const FixedPointResult plain = solve_fixed_point(linear_map(0.45), 4, settings(), 1e-6);
  const FixedPointResult fast = solve_fixed_point(linear_map(0.45), 4, settings(FixedPointVariant::Accelerated), 1e-6);
  ASSERT_EQ(plain.status, FixedPointStatus::Converged);
  ASSERT_EQ(fast.status, FixedPointStatus::Converged);
  EXPECT_GE(plain.iterations(), 12);
  EXPECT_GT(steps_made_by(fast, FixedPointUpdate::Relaxed), 0);
  EXPECT_LE(fast.iterations(), plain.iterations() / 2);
}

TEST(FixedPoint, InnerNoiseTightensTheQpToleranceInsteadOfStagnating) {
  // Noise of 1e3·rtol in G: at rtol = 1e-6 it is 1e-3, far above tol = 1e-4 (the old noise floor).
  // Without the schedule tied to err, the stall is detected and the tolerance tightened.
  FixedPointSettings detect = settings();
  detect.qp_rtol_per_err = 0;
  const FixedPointResult r = solve_fixed_point(linear_map(0.3, 1e3), 5, detect, 1e-6);
  EXPECT_EQ(r.status, FixedPointStatus::Converged);
  EXPECT_GE(r.qp_tolerance_tightenings, 1);
  EXPECT_LT(r.history.back().qp_rtol, 1e-6);
  // With the paper's fixed tolerance the same map stalls on the noise.
  FixedPointSettings fixed = settings();
  fixed.adaptive_qp_tolerance = false;
  EXPECT_NE(solve_fixed_point(linear_map(0.3, 1e3), 5, fixed, 1e-6).status, FixedPointStatus::Converged);
}

TEST(FixedPoint, QpToleranceFollowsErrSoNoiseNeverStalls) {
  // The default schedule: step k at min(qp_rtol, qp_rtol_per_err·err(k−1)). The noisy map converges
  // with no stall to detect, in the steps of the noise-free map, and each step's tolerance follows err.
  const FixedPointResult noisy = solve_fixed_point(linear_map(0.3, 1e3), 5, settings(), 1e-6);
  const FixedPointResult clean = solve_fixed_point(linear_map(0.3), 5, settings(), 1e-6);
  ASSERT_EQ(noisy.status, FixedPointStatus::Converged);
  EXPECT_EQ(noisy.qp_tolerance_tightenings, 0);
  EXPECT_EQ(noisy.iterations(), clean.iterations());
  const double eta = FixedPointSettings{}.qp_rtol_per_err;
  EXPECT_DOUBLE_EQ(noisy.history[0].qp_rtol, 1e-6);
  for (int k = 1; k < noisy.iterations(); ++k)
    EXPECT_DOUBLE_EQ(noisy.history[k].qp_rtol, std::min(1e-6, std::max(1e-12, eta * noisy.history[k - 1].err)));
}

TEST(FixedPoint, RelaxationConvergesWhereThePlainIterationOscillatesApart) {
  // G(φ) = φ* − 1.5 (φ − φ*): plain steps oscillate with growing amplitude; Aitken's ω → 1/2.5
  // makes it exact in a few steps, and the default hands over to it after the first growing step.
  FixedPointSettings plain = settings();
  plain.max_iterations = 30;
  EXPECT_NE(solve_fixed_point(linear_map(-1.5), 4, plain, 1e-6).status, FixedPointStatus::Converged);
  for (FixedPointVariant v : {FixedPointVariant::Aitken, FixedPointVariant::Accelerated}) {
    const FixedPointResult r = solve_fixed_point(linear_map(-1.5), 4, settings(v), 1e-6);
    EXPECT_EQ(r.status, FixedPointStatus::Converged) << static_cast<int>(v);
    EXPECT_LE(r.iterations(), 6) << static_cast<int>(v);
  }
}

// G oscillates between two points: no contraction however tight the QP (`qp_iterations` per step).
SlipMap two_cycle_map(int qp_iterations = 0) {
  return [qp_iterations](const Eigen::VectorXd& phi, double) {
    SlipEvaluation e;
    e.slip = phi.sum() > 0.5 * phi.size() ? Eigen::VectorXd::Zero(phi.size()).eval()
                                          : Eigen::VectorXd::Ones(phi.size()).eval();
    e.slip[0] += 0.1;
    e.qp_iterations = qp_iterations;
    return e;
  };
}

TEST(FixedPoint, StagnationOnlyWhenTheMapDoesNotContract) {
  const SlipMap two_cycle = two_cycle_map();
  FixedPointSettings s = settings();
  s.max_iterations = 200;
  const FixedPointResult r = solve_fixed_point(two_cycle, 3, s, 1e-6);
  EXPECT_EQ(r.status, FixedPointStatus::Stagnation);
  EXPECT_LE(r.history.back().qp_rtol, s.qp_rtol_floor);  // the inner tolerance was ruled out first
  EXPECT_GE(r.contraction_factor, 1.0);
  EXPECT_TRUE(std::isinf(r.distance_bound));
  EXPECT_NE(r.hint.find("does not contract"), std::string::npos);
}

// A tolerance below what the inner solves can give: a contraction whose every evaluation carries a
// rounding of 3e-12 that no tighter QP removes stalls near it. The hint says so, not that the law is
// too steep (the L-block asked for 1e-12 was told its map "does not contract").
TEST(FixedPoint, StallAtTheQpRoundingIsSaidAsSuch) {
  const SlipMap rounded = [flip = 0](const Eigen::VectorXd& phi, double) mutable {
    const Eigen::VectorXd star = Eigen::VectorXd::LinSpaced(phi.size(), 1.0, 2.0);
    SlipEvaluation e;
    flip = 1 - flip;
    e.slip = star + 0.3 * (phi - star) + (flip ? 3e-12 : -3e-12) * Eigen::VectorXd::Ones(phi.size());
    e.qp_iterations = 1;
    e.hessian_products = 2;
    return e;
  };
  FixedPointSettings s = settings();
  s.tol = 1e-14;
  s.max_iterations = 200;
  const FixedPointResult r = solve_fixed_point(rounded, 3, s, 1e-6);
  EXPECT_NE(r.status, FixedPointStatus::Converged);
  EXPECT_NE(r.hint.find("rounding of the QP solves"), std::string::npos) << r.hint;
  EXPECT_EQ(r.hint.find("does not contract"), std::string::npos) << r.hint;
}

// A map that returns its input wherever it may stop loosely (a QP kept at its warm start: err 0 after 0
// iterations) and cycles when solved tightly: its stagnation is not a stall at the QPs' rounding (a
// strip with a ramp law was told a solver.fixed_point_tol "below about 0" could not be reached).
TEST(FixedPoint, StepsThatKeepTheirWarmStartAreNoRoundingLevel) {
  const SlipMap two_cycle = two_cycle_map(1);
  const SlipMap lazy = [two_cycle](const Eigen::VectorXd& phi, double rtol) mutable {
    if (rtol > 1e-9) {
      SlipEvaluation e;
      e.slip = phi;
      return e;
    }
    return two_cycle(phi, rtol);
  };
  FixedPointSettings s = settings();
  s.max_iterations = 60;
  const FixedPointResult r = solve_fixed_point(lazy, 3, s, 1e-6);
  ASSERT_NE(r.status, FixedPointStatus::Converged);
  EXPECT_EQ(r.hint.find("below about 0 "), std::string::npos) << r.hint;
  EXPECT_EQ(r.hint.find("rounding of the QP solves"), std::string::npos) << r.hint;
}

TEST(FixedPoint, NoStagnationWhileTheIteratesTravelOneWay) {
  // A front that feeds on itself (G = φ + φ²/20 + 1, capped at 40, as slip spreading over a large
  // face): err rises for three steps after its minimum while every residual points the same way,
  // then the cap is reached. With a window of 3 that rise must not be called stagnation.
  SlipMap spreading = [](const Eigen::VectorXd& phi, double) {
    SlipEvaluation e;
    e.slip = phi.unaryExpr([](double t) { return std::min(t + 0.05 * t * t + 1, 40.0); });
    e.qp_iterations = 100;  // a busy QP: not inner noise
    return e;
  };
  FixedPointSettings s = settings();
  s.stagnation_window = 3;
  const FixedPointResult r = solve_fixed_point(spreading, 3, s, 1e-6);
  EXPECT_EQ(r.status, FixedPointStatus::Converged);
  // 10 steps to the cap, which the run reaches abruptly (err 0.1 → 0): the 11th repeats the last at
  // the final step's QP tolerance.
  EXPECT_EQ(r.iterations(), 11);
  EXPECT_EQ(r.history.back().update, FixedPointUpdate::Repeat);
  EXPECT_GT(r.history[7].err, r.history[4].err);  // three steps without a new minimum on the way
  EXPECT_NEAR(r.phi[0], 40.0, 1e-12);
}

TEST(FixedPoint, ARunThatConvergesAbruptlyRepeatsItsLastStepAtTheFinalQpTolerance) {
  // G jumps to its fixed point from any φ (as Coulomb with every cell sticking: err 1, then 0). The
  // step that meets tol was solved to qp_rtol (eta·err(k−1) = 1e-6 is not below it), so it is
  // repeated at final_step_qp_rtol, the tolerance a one-QP problem and a gradual run's last step get.
  SlipMap jump = [](const Eigen::VectorXd& phi, double) {
    SlipEvaluation e;
    e.slip = Eigen::VectorXd::LinSpaced(phi.size(), 1.0, 2.0);
    e.qp_iterations = 10;
    return e;
  };
  const FixedPointSettings s = settings();
  const FixedPointResult r = solve_fixed_point(jump, 3, s, 1e-6);
  ASSERT_EQ(r.status, FixedPointStatus::Converged);
  ASSERT_EQ(r.iterations(), 3);
  EXPECT_DOUBLE_EQ(r.history[1].qp_rtol, 1e-6);
  EXPECT_LE(r.history[1].err, s.tol);
  EXPECT_EQ(r.history[2].update, FixedPointUpdate::Repeat);
  EXPECT_DOUBLE_EQ(r.history[2].qp_rtol, final_step_qp_rtol(s, 1e-6));
  // A gradual contraction ends within 100× of that tolerance and takes no repeat; nor does a run
  // whose QP tolerance does not follow err (the paper's qp_rtol in every step).
  const FixedPointResult gradual = solve_fixed_point(linear_map(0.5), 3, s, 1e-6);
  ASSERT_EQ(gradual.status, FixedPointStatus::Converged);
  EXPECT_EQ(steps_made_by(gradual, FixedPointUpdate::Repeat), 0);
  EXPECT_LE(gradual.history.back().qp_rtol, 100 * final_step_qp_rtol(s, 1e-6));
  FixedPointSettings paper = s;
  paper.qp_rtol_per_err = 0;
  EXPECT_EQ(solve_fixed_point(jump, 3, paper, 1e-6).iterations(), 2);
}

TEST(FixedPoint, TheFinalStepsRepeatIsNotCountedAsAStepOfTheMap) {
  // Contraction 0.4 until φ is within 0.1 of φ*, then 1e-3 (as after a predicted step): the step
  // that meets tol follows one of err > 1e-2, so it is repeated at the final QP tolerance. The
  // repeat evaluates the same φ again; counted as a step of its own its length (equal to the last
  // one's) gave q = 1 and no a posteriori bound (the puck, steep law: q 1.0002, bound ∞).
  const Eigen::VectorXd fixed = Eigen::VectorXd::LinSpaced(3, 1.0, 2.0);
  SlipMap landing = [&fixed](const Eigen::VectorXd& phi, double) {
    SlipEvaluation e;
    const Eigen::VectorXd d = phi - fixed;
    e.slip = fixed + (d.cwiseAbs().maxCoeff() > 0.1 ? 0.4 : 1e-3) * d;
    e.qp_iterations = 10;
    return e;
  };
  FixedPointSettings s = settings();
  s.variant = FixedPointVariant::Plain;
  const FixedPointResult r = solve_fixed_point(landing, 3, s, 1e-6);
  ASSERT_EQ(r.status, FixedPointStatus::Converged);
  ASSERT_EQ(r.history.back().update, FixedPointUpdate::Repeat);
  EXPECT_LT(r.contraction_factor, 0.7);  // the landing's step against the one before: 0.4 / 0.6
  EXPECT_TRUE(std::isfinite(r.distance_bound));
  EXPECT_LT(r.distance_bound, 10 * r.history.back().err);
}

TEST(FixedPoint, RelaxationTakesPlainStepsWhileTheResidualGrowsAlongTheStep) {
  // Positive feedback far from the fixed point (G = 3φ + 1 below 4.5, as slip weakening from
  // φ⁰ = 0), then an oscillating contraction (slope −0.5) around φ* = 67/6. The secant of the first
  // steps is negative: plain steps must be taken there (6 steps), not ω shrunk to its floor (11).
  SlipMap feedback = [](const Eigen::VectorXd& phi, double) {
    SlipEvaluation e;
    e.slip = phi.unaryExpr([](double t) { return t < 4.5 ? 3 * t + 1 : 14.5 - 0.5 * (t - 4.5); });
    return e;
  };
  const FixedPointResult plain = solve_fixed_point(feedback, 3, settings(), 1e-6);
  ASSERT_EQ(plain.status, FixedPointStatus::Converged);
  for (FixedPointVariant v : {FixedPointVariant::Aitken, FixedPointVariant::Accelerated}) {
    const FixedPointResult r = solve_fixed_point(feedback, 3, settings(v), 1e-6);
    ASSERT_EQ(r.status, FixedPointStatus::Converged) << static_cast<int>(v);
    EXPECT_LE(r.iterations(), 7) << static_cast<int>(v);
    EXPECT_LT(r.iterations(), plain.iterations());
    EXPECT_NEAR(r.phi[0], 67.0 / 6.0, 1e-3);
  }
}

TEST(FixedPoint, RelaxationKeepsItsLongStepsWhileTheIteratesRunAway) {
  // Residual r(φ) = G(φ) − φ: a slow contraction below φ = 1 (G′ = 0.6: Aitken lengthens the steps,
  // ω = 2.5 and more), then feedback (G′ = 1.5: r grows along itself, the secant is negative) up to
  // φ = 5, then an oscillating contraction (G′ = −0.5) to φ* = 6.4. In the runaway the relaxation
  // keeps ω (here 4) rather than falling back to the plain step.
  SlipMap runaway = [](const Eigen::VectorXd& phi, double) {
    SlipEvaluation e;
    e.slip = phi.unaryExpr([](double t) {
      const double r = t < 1 ? 0.5 - 0.4 * t : t < 5 ? 0.1 + 0.5 * (t - 1) : 2.1 - 1.5 * (t - 5);
      return t + r;
    });
    return e;
  };
  const FixedPointResult plain = solve_fixed_point(runaway, 1, settings(), 1e-8);
  const FixedPointResult aitken = solve_fixed_point(runaway, 1, settings(FixedPointVariant::Aitken), 1e-8);
  ASSERT_EQ(plain.status, FixedPointStatus::Converged);
  ASSERT_EQ(aitken.status, FixedPointStatus::Converged);
  EXPECT_NEAR(aitken.phi[0], 6.4, 1e-6);
  EXPECT_LE(aitken.iterations(), 8);  // resetting ω to 1 in the runaway: 9 steps
  EXPECT_LT(aitken.iterations(), plain.iterations());
}

TEST(FixedPoint, RelaxationTakesPlainStepsWhereResidualsTurnAtAWideAngle) {
  // G(φ) = φ* + 0.6 R (φ − φ*), R a quarter turn: each plain residual is the last one turned by 90°,
  // so the secant (1/1.36 here) says nothing of a rate along it. Aitken must take the plain steps.
  SlipMap turning = [](const Eigen::VectorXd& phi, double) {
    const Eigen::Vector2d star(10.0, 10.0), e = phi - star;
    SlipEvaluation out;
    out.slip = star + 0.6 * Eigen::Vector2d(-e[1], e[0]);
    out.qp_iterations = 100;
    return out;
  };
  const FixedPointResult plain = solve_fixed_point(turning, 2, settings(), 1e-6);
  const FixedPointResult aitken = solve_fixed_point(turning, 2, settings(FixedPointVariant::Aitken), 1e-6);
  ASSERT_EQ(plain.status, FixedPointStatus::Converged);
  ASSERT_EQ(aitken.status, FixedPointStatus::Converged);
  ASSERT_EQ(aitken.iterations(), plain.iterations());
  for (std::size_t k = 0; k < plain.history.size(); ++k)
    EXPECT_NEAR(aitken.history[k].err, plain.history[k].err, 1e-12 * plain.history[k].err) << "step " << k + 1;
}

TEST(FixedPoint, NoStagnationWhileErrFallsAfterARise) {
  // G ignores φ and returns c + (−1)ᵏ aₖ (1, 1, 1): the residuals flip each step (not travelling);
  // err reaches 2e-4 at step 3, rises for three steps (as when a slip front spreads) and then falls
  // by 0.85 per step. The window of 8 steps without a new minimum ends while err is falling: that is
  // convergence, not stagnation.
  SlipMap rise_then_fall = [k = 0](const Eigen::VectorXd& phi, double) mutable {
    ++k;
    const double a = k <= 3 ? 1e-3 : k <= 6 ? 1e-3 * std::pow(8.0, k - 3) : 0.512 * std::pow(0.85, k - 6);
    SlipEvaluation e;
    e.slip = Eigen::VectorXd::Constant(phi.size(), 10.0 + (k % 2 ? a : -a));
    e.qp_iterations = 100;  // a busy QP: not inner noise
    return e;
  };
  const FixedPointResult r = solve_fixed_point(rise_then_fall, 3, settings(), 1e-6);
  EXPECT_EQ(r.status, FixedPointStatus::Converged);
  EXPECT_GT(r.iterations(), 3 + settings().stagnation_window);  // the window did run out on the way
}

TEST(FixedPoint, AcceleratedFallsBackToPlainStepsBeforeCallingStagnation) {
  // A map that contracts (q = 0.5 towards φ* = 1) only along its own plain steps, and answers any
  // other input (a relaxed or mixed iterate) with a point that is no better — as a slow slip front
  // that plain steps ride out and the mixing breaks up (Coulomb with a jump law on the L-block).
  SlipMap fragile = [last = Eigen::VectorXd(), sign = 1.0](const Eigen::VectorXd& phi, double) mutable {
    SlipEvaluation e;
    const bool plain_step = last.size() == phi.size() && (phi - last).norm() == 0;
    sign = -sign;
    e.slip = plain_step
                 ? (1.0 + 0.5 * (phi.array() - 1.0)).matrix().eval()
                 : Eigen::VectorXd::Constant(phi.size(), 5.0 + 2.0 * sign).eval();  // 3, 7, 3, ...: no fixed point
    e.qp_iterations = 100;                                                          // a busy QP: not inner noise
    last = e.slip;
    return e;
  };
  for (FixedPointVariant v : {FixedPointVariant::Aitken, FixedPointVariant::Anderson}) {
    const FixedPointResult r = solve_fixed_point(fragile, 3, settings(v), 1e-6);
    ASSERT_EQ(r.status, FixedPointStatus::Converged) << static_cast<int>(v);
    EXPECT_GT(r.plain_fallback_step, 0) << static_cast<int>(v);
    EXPECT_NEAR(r.phi[0], 1.0, 1e-3);
  }
  const FixedPointResult plain = solve_fixed_point(fragile, 3, settings(), 1e-6);
  EXPECT_EQ(plain.status, FixedPointStatus::Converged);
  EXPECT_EQ(plain.plain_fallback_step, 0);
}

TEST(FixedPoint, StagnationAfterTheFallbackWhenPlainStepsDoNotContractEither) {
  const SlipMap two_cycle = two_cycle_map(100);  // a busy QP: not inner noise
  FixedPointSettings s = settings(FixedPointVariant::Accelerated);
  s.max_iterations = 200;
  const FixedPointResult r = solve_fixed_point(two_cycle, 3, s, 1e-6);
  EXPECT_EQ(r.status, FixedPointStatus::Stagnation);
  EXPECT_GT(r.plain_fallback_step, 0);
  EXPECT_GE(r.iterations(), r.plain_fallback_step + s.stagnation_window);
}

// G(φ) = φ* + diag(rates)(φ − φ*), φ* = scale·(1, 2, ...): one rate per component.
SlipMap diagonal_map(const std::vector<double>& rates, const std::vector<double>& scale) {
  return [=](const Eigen::VectorXd& phi, double) {
    SlipEvaluation e;
    e.slip.resize(phi.size());
    for (Eigen::Index i = 0; i < phi.size(); ++i) {
      const double star = scale[i] * static_cast<double>(i + 1);
      e.slip[i] = star + rates[i] * (phi[i] - star);
    }
    e.qp_iterations = 100;
    return e;
  };
}

TEST(FixedPoint, AcceleratedMixesTheTailWhereNoSingleRelaxationFactorFitsEveryRate) {
  // Rates 0.9 and −0.8 at once: ω = 1/(1 − 0.9) = 10 would fit the first and blow up the second, ω
  // = 1/1.8 the reverse. Anderson's multisecant fit takes both once the tail is reached.
  const std::vector<double> rates{0.9, -0.8, 0.6, 0.3}, unit(4, 1.0);
  FixedPointSettings relax_only = settings(FixedPointVariant::Accelerated);
  relax_only.tail_err = 0;
  const FixedPointResult relaxed = solve_fixed_point(diagonal_map(rates, unit), 4, relax_only, 1e-6);
  const FixedPointResult mixed =
      solve_fixed_point(diagonal_map(rates, unit), 4, settings(FixedPointVariant::Accelerated), 1e-6);
  ASSERT_EQ(relaxed.status, FixedPointStatus::Converged);
  ASSERT_EQ(mixed.status, FixedPointStatus::Converged);
  EXPECT_EQ(relaxed.mixed_steps, 0);
  EXPECT_GT(mixed.mixed_steps, 0);
  EXPECT_LT(mixed.iterations(), relaxed.iterations() - 3);
  for (Eigen::Index i = 0; i < 4; ++i) EXPECT_NEAR(mixed.phi[i], i + 1.0, 1e-3 * (i + 1));
  // Each step says how its input was made: the count of mixed inputs is mixed_steps, the first
  // input is φ⁰ = 0, and the relaxation-only run relaxes after its plain steps.
  EXPECT_EQ(steps_made_by(mixed, FixedPointUpdate::Mixed), mixed.mixed_steps);
  EXPECT_EQ(mixed.history.front().update, FixedPointUpdate::Start);
  EXPECT_EQ(steps_made_by(relaxed, FixedPointUpdate::Mixed), 0);
  EXPECT_GT(steps_made_by(relaxed, FixedPointUpdate::Relaxed), 0);
}

TEST(FixedPoint, TailMixingFitsEveryBlockOfTheStateWhateverItsUnits) {
  // Coulomb's state: slips (~1e-6 m) and pressures (~1e7 Pa), ten of each with rates spread over
  // (−0.9, 0.9), more directions than the mixing's depth. Unweighted, the least-squares fit sees
  // only the pressures and the slips keep their slow rates; weighted per block (block_weights), the
  // scaled state converges as the same state in unit scale does.
  std::vector<double> rates, unit(20, 1.0), scaled;
  for (int j = 0; j < 20; ++j) {
    rates.push_back(0.9 * std::cos(0.37 * j + 0.2));
    scaled.push_back(j < 10 ? 1e-6 : 1e7);
  }
  FixedPointSettings s = settings(FixedPointVariant::Accelerated);
  s.blocks = {10, 10};
  const FixedPointResult alone = solve_fixed_point(diagonal_map(rates, unit), 20, s, 1e-6);
  const FixedPointResult units = solve_fixed_point(diagonal_map(rates, scaled), 20, s, 1e-6);
  ASSERT_EQ(alone.status, FixedPointStatus::Converged);
  ASSERT_EQ(units.status, FixedPointStatus::Converged);
  EXPECT_LE(units.iterations(), alone.iterations() + 1);
  EXPECT_NEAR(units.phi[0], 1e-6, 1e-9);
  EXPECT_NEAR(units.phi[1], 2e-6, 2e-9);
}

// G answers any iterate off the lines of its earlier steps (φ, G(φ)) — a mixed or Newton iterate; a plain
// or relaxed one lies on such a line — with a worse point, 1.5 G(φ).
SlipMap spoiled_off_its_lines(SlipMap G) {
  return [G = std::move(G), steps = std::vector<std::pair<Eigen::VectorXd, Eigen::VectorXd>>()](
             const Eigen::VectorXd& phi, double rtol) mutable {
    SlipEvaluation e = G(phi, rtol);
    auto on_line = [&phi](const std::pair<Eigen::VectorXd, Eigen::VectorXd>& s) {
      const Eigen::VectorXd step = phi - s.first, line = (s.second - s.first).normalized();
      return (step - step.dot(line) * line).norm() <= 1e-6 * step.norm();
    };
    if (!steps.empty() && std::none_of(steps.begin(), steps.end(), on_line)) e.slip *= 1.5;
    steps.emplace_back(phi, e.slip);
    return e;
  };
}

TEST(FixedPoint, TailMixingThatRaisesErrHandsBackToTheRelaxation) {
  // A contraction with different rates (so the tail is mixed) that answers any iterate off the lines
  // of its earlier steps — a mixed one; a plain or relaxed iterate lies on one — with a worse point:
  // the run must still converge, relaxing for good after two mixed steps that raised err (two
  // episodes), each rejected (the relaxation goes on from the step before it).
  const FixedPointResult r = solve_fixed_point(spoiled_off_its_lines(diagonal_map({0.8, 0.6, 0.5}, {1, 1, 1})), 3,
                                               settings(FixedPointVariant::Accelerated), 1e-6);
  EXPECT_EQ(r.status, FixedPointStatus::Converged);
  // Two episodes of at most two mixed iterates (the mixing's first iterate is G(x) itself — one pair,
  // on the line — and counts as a plain step, not judged as the mixing's); without the safeguard the
  // run mixes 14 times and takes 36 steps. Each raised err, so each episode ends in a restart.
  EXPECT_LE(r.mixed_steps, 4);
  EXPECT_EQ(steps_made_by(r, FixedPointUpdate::Mixed), r.mixed_steps);
  EXPECT_GE(steps_made_by(r, FixedPointUpdate::Restart), 1);
  EXPECT_LE(r.iterations(), 20);
  for (Eigen::Index i = 0; i < 3; ++i) EXPECT_NEAR(r.phi[i], i + 1.0, 5e-3 * (i + 1));  // q = 0.8: 5 err
}

// G(φ) = φ* + A(φ − φ*) + (φ − φ*)²/4 componentwise, A = diag(rates), with its derivative (the
// Tresca map's comes from the QP's sensitivity to the radii; `derivative_products` per product).
SlipMap smooth_map_with_derivative(const std::vector<double>& rates, int derivative_products) {
  return [=](const Eigen::VectorXd& phi, double) {
    SlipEvaluation e;
    const Eigen::VectorXd star = Eigen::VectorXd::LinSpaced(phi.size(), 1.0, 2.0);
    const Eigen::VectorXd a = Eigen::Map<const Eigen::VectorXd>(rates.data(), phi.size());
    const Eigen::VectorXd d = phi - star;
    e.slip = star + a.cwiseProduct(d) + 0.25 * d.cwiseAbs2();
    e.qp_iterations = 100;
    e.hessian_products = 100;
    auto products = std::make_shared<int>(0);  // the running total SlipEvaluation::derivative_products reads
    e.derivative = [a, d, products, derivative_products](const Eigen::VectorXd& v) {
      *products += derivative_products;
      return Eigen::VectorXd((a + 0.5 * d).cwiseProduct(v));
    };
    e.derivative_products = [products] { return *products; };
    return e;
  };
}

TEST(FixedPoint, NewtonStepsInTheTailConvergeFasterThanRelaxationOrMixing) {
  const std::vector<double> rates{0.9, -0.8, 0.6, 0.95};
  FixedPointSettings without = settings(FixedPointVariant::Accelerated);
  without.newton = false;
  const FixedPointResult mixed = solve_fixed_point(smooth_map_with_derivative(rates, 3), 4, without, 1e-6);
  const FixedPointResult newton =
      solve_fixed_point(smooth_map_with_derivative(rates, 3), 4, settings(FixedPointVariant::Accelerated), 1e-6);
  ASSERT_EQ(mixed.status, FixedPointStatus::Converged);
  ASSERT_EQ(newton.status, FixedPointStatus::Converged);
  EXPECT_EQ(mixed.newton_steps, 0);
  EXPECT_GT(newton.newton_steps, 0);
  EXPECT_EQ(steps_made_by(newton, FixedPointUpdate::Newton), newton.newton_steps);
  EXPECT_LT(newton.iterations(), mixed.iterations());
  // Once Newton runs err falls at least fivefold per step (the relaxation's rate here is 0.95 at
  // best; GMRES solves each Newton system to 1e-2).
  const int first = newton.iterations() - newton.newton_steps - 1;
  for (int k = first + 2; k < newton.iterations(); ++k)
    EXPECT_LT(newton.history[k].err, 0.25 * newton.history[k - 1].err) << "step " << k + 1;
  // The a posteriori bound is the map's, not the Newton steps': q is ‖G′‖ (0.95 here, estimated on
  // the Krylov space) however fast the steps fell, so the bound is 19 err, not a fraction of it.
  EXPECT_GT(newton.contraction_factor, 0.9);
  EXPECT_LT(newton.contraction_factor, 0.96);
  EXPECT_GT(newton.distance_bound, 10 * newton.history.back().err);
  // n_mult counts the derivative products: more than the evaluations' 100 per step.
  EXPECT_GT(newton.history.back().n_mult, 100 * newton.iterations());
  for (Eigen::Index i = 0; i < 4; ++i) EXPECT_NEAR(newton.phi[i], 1.0 + i / 3.0, 5e-3);  // rate 0.95: 20 err
  // Plain and Aitken never take Newton steps.
  for (FixedPointVariant v : {FixedPointVariant::Plain, FixedPointVariant::Aitken})
    EXPECT_EQ(solve_fixed_point(smooth_map_with_derivative(rates, 3), 4, settings(v), 1e-6).newton_steps, 0);
  // The paper's iteration: every input after φ⁰ is G of the one before.
  const FixedPointResult plain =
      solve_fixed_point(smooth_map_with_derivative(rates, 3), 4, settings(FixedPointVariant::Plain), 1e-6);
  EXPECT_EQ(steps_made_by(plain, FixedPointUpdate::Plain), plain.iterations() - 1);
}

TEST(FixedPoint, TwoTailStepsThatRaiseErrEndTheTailForNewtonAndMixingAlike) {
  // A map with a derivative (so the tail takes Newton steps) and different rates (so mixing would
  // fit it) that answers any iterate off the lines of its earlier steps — a Newton or mixed one — with
  // a worse point, as a law with a jump answers an iterate that moves nodes across the jump. After two
  // tail steps that raised err the run must relax for good: two Newton steps, each rejected, and no
  // mixed step after them (before this rule the mixing then raised err twice more).
  const std::vector<double> rates{0.9, -0.8, 0.6, 0.3};
  SlipMap with_derivative = [G = diagonal_map(rates, {1, 1, 1, 1}), rates](const Eigen::VectorXd& phi, double rtol) {
    SlipEvaluation e = G(phi, rtol);
    e.derivative = [rates](const Eigen::VectorXd& v) {
      return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(rates.data(), v.size()).cwiseProduct(v));
    };
    return e;
  };
  const FixedPointResult r =
      solve_fixed_point(spoiled_off_its_lines(with_derivative), 4, settings(FixedPointVariant::Accelerated), 1e-6);
  EXPECT_EQ(r.status, FixedPointStatus::Converged);
  EXPECT_EQ(r.newton_steps, 2);
  EXPECT_EQ(r.mixed_steps, 0);
  EXPECT_EQ(steps_made_by(r, FixedPointUpdate::Restart), 2);
  // After the second restart every input is relaxed (or plain): no tail step comes back.
  const auto last_restart = std::find_if(r.history.rbegin(), r.history.rend(),
                                         [](const FixedPointStep& s) { return s.update == FixedPointUpdate::Restart; });
  for (auto it = r.history.rbegin(); it != last_restart; ++it)
    EXPECT_TRUE(it->update == FixedPointUpdate::Relaxed || it->update == FixedPointUpdate::Plain);
  for (Eigen::Index i = 0; i < 4; ++i) EXPECT_NEAR(r.phi[i], i + 1.0, 5e-3 * (i + 1));
}

TEST(FixedPoint, TheNewtonTrustRegionGrowsAgainAfterARejectedStep) {
  // The smooth map with its derivative (rates up to 0.95: a Newton step is about ten plain steps long),
  // whose first Newton iterate is answered with a worse point (as a jump of the law answers one): that
  // step is rejected and the trust region cut to half its length. Later Newton steps, which the region
  // cuts but which cut err, must let it grow again: before they did not, and every later step went
  // about half the way (err falling by one half per step, as a Coulomb strip showed for 12 steps).
  const std::vector<double> rates{0.9, -0.8, 0.6, 0.95};
  SlipMap G = smooth_map_with_derivative(rates, 3);
  // The first evaluation after the derivative was first used is at the first Newton iterate.
  auto derivative_used = std::make_shared<bool>(false);
  SlipMap spoiled_once = [G, derivative_used, spoiled = false](const Eigen::VectorXd& phi, double rtol) mutable {
    SlipEvaluation e = G(phi, rtol);
    if (*derivative_used && !spoiled) {
      spoiled = true;
      e.slip *= 1.5;
    }
    e.derivative = [inner = e.derivative, derivative_used](const Eigen::VectorXd& v) {
      *derivative_used = true;
      return inner(v);
    };
    return e;
  };
  const FixedPointResult r = solve_fixed_point(spoiled_once, 4, settings(FixedPointVariant::Accelerated), 1e-6);
  ASSERT_EQ(r.status, FixedPointStatus::Converged);
  EXPECT_EQ(steps_made_by(r, FixedPointUpdate::Restart), 1);
  // After the restart the Newton steps converge fast again: the run ends within 8 steps of it (7 here;
  // without the region growing back 31: the capped Newton steps crept, failed, and the relaxation
  // finished).
  const auto restart = std::find_if(r.history.begin(), r.history.end(),
                                    [](const FixedPointStep& s) { return s.update == FixedPointUpdate::Restart; });
  ASSERT_NE(restart, r.history.end());
  EXPECT_LE(r.history.end() - restart, 8) << "steps after the restart";
  for (Eigen::Index i = 0; i < 4; ++i) EXPECT_NEAR(r.phi[i], 1.0 + i / 3.0, 5e-3);  // rate 0.95: 20 err
}

// A slip front on a chain of n nodes with a law that jumps: F = 0.3 below a slip of 1, 0.15 above.
// G(φ)_i = b_i + Σ_j A_ij (0.3 − F(φ_j)), A tridiagonal (4/3 on the diagonal, 2/3 beside it): a node
// that crosses the jump pushes its neighbours' slip up by 0.1, enough to take the next node across
// while b_i = 1.05 − 0.01 i ≥ 0.9 — node by node to node 15, a node or two per plain step. G is affine in
// the coefficients, so the prediction G(x) + A(c(y) − c(x)) is exact (the Tresca step's prediction is
// where the QP's active sets stay), and `wrong_prediction` replaces it by another rule.
SlipMap jump_front(
    int n,
    std::function<Eigen::VectorXd(const Eigen::VectorXd& gx, const Eigen::VectorXd& y)> wrong_prediction = nullptr) {
  auto coefficient_drop = [](const Eigen::VectorXd& phi) {
    return Eigen::VectorXd(phi.unaryExpr([](double t) { return t < 1.0 ? 0.0 : 0.15; }));
  };
  auto response = [n](const Eigen::VectorXd& drop) {
    Eigen::VectorXd out = 4.0 / 3.0 * drop;
    out.head(n - 1) += 2.0 / 3.0 * drop.tail(n - 1);
    out.tail(n - 1) += 2.0 / 3.0 * drop.head(n - 1);
    return out;
  };
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, 1.05, 1.05 - 0.01 * (n - 1));
  return [=](const Eigen::VectorXd& phi, double) {
    SlipEvaluation e;
    e.slip = b + response(coefficient_drop(phi));
    e.qp_iterations = 10;
    e.hessian_products = 20;
    const Eigen::VectorXd gx = e.slip;
    auto products = std::make_shared<int>(0);  // 3 per prediction, as a Tresca step's
    if (wrong_prediction)
      e.predict = [=](const Eigen::VectorXd& y) {
        *products += 3;
        return wrong_prediction(gx, y);
      };
    else
      e.predict = [=](const Eigen::VectorXd& y) {
        *products += 3;
        return Eigen::VectorXd(gx + response(coefficient_drop(y) - coefficient_drop(phi)));
      };
    e.derivative_products = [products] { return *products; };
    return e;
  };
}

TEST(FixedPoint, PredictedStepsTakeASlipFrontAcrossAJumpInTheirOwnIterations) {
  const int n = 30;
  const FixedPointResult plain = solve_fixed_point(jump_front(n), n, settings(FixedPointVariant::Plain), 1e-6);
  const FixedPointResult predicted =
      solve_fixed_point(jump_front(n), n, settings(FixedPointVariant::Accelerated), 1e-6);
  FixedPointSettings off = settings(FixedPointVariant::Accelerated);
  off.predicted_steps = false;
  const FixedPointResult without = solve_fixed_point(jump_front(n), n, off, 1e-6);
  ASSERT_EQ(plain.status, FixedPointStatus::Converged);
  ASSERT_EQ(predicted.status, FixedPointStatus::Converged);
  ASSERT_EQ(without.status, FixedPointStatus::Converged);
  // The plain iteration moves the front a node or two per step: 16 nodes cross in 12 steps.
  EXPECT_GE(plain.iterations(), 12);
  EXPECT_EQ(plain.predicted_steps, 0);
  EXPECT_EQ(without.predicted_steps, 0);
  // The accelerated run relaxes from its fourth step on (the third still halved the step), and its
  // first predicted step lands on the fixed point (err 0, then the final step's repeat).
  EXPECT_EQ(predicted.predicted_steps, 1);
  EXPECT_EQ(steps_made_by(predicted, FixedPointUpdate::Predicted), 1);
  EXPECT_LE(predicted.iterations(), 6);
  EXPECT_LT(predicted.iterations(), without.iterations());
  // The same fixed point as the paper's iteration (with a jump there are others: node 16 across
  // would hold itself there too).
  EXPECT_LT((predicted.phi - plain.phi).lpNorm<Eigen::Infinity>(), 1e-12);
  for (int i = 0; i < n; ++i) EXPECT_EQ(plain.phi[i] >= 1.0, i <= 15) << i;
  // n_mult counts the predictions (3 products each) beside the evaluations' 20.
  EXPECT_GT(predicted.history.back().n_mult, 20 * predicted.iterations());
}

TEST(FixedPoint, APredictionThatDoesNotConvergeOrCyclesHandsBackToTheRelaxation) {
  const int n = 30;
  // Iterations that never settle (each prediction moves every slip up by 1): every try fails, two
  // tries and the run goes on without predictions — and still converges, by its relaxation.
  const FixedPointResult restless = solve_fixed_point(
      jump_front(n, [](const Eigen::VectorXd&,
                       const Eigen::VectorXd& y) { return Eigen::VectorXd(y + Eigen::VectorXd::Ones(y.size())); }),
      n, settings(FixedPointVariant::Accelerated), 1e-6);
  EXPECT_EQ(restless.status, FixedPointStatus::Converged);
  EXPECT_EQ(restless.predicted_steps, 0);
  // Its n_mult: 20 per evaluation, and the two tries' 60 predictions of 3 products each.
  EXPECT_EQ(restless.history.back().n_mult, 20 * restless.iterations() + 2 * 60 * 3);
  // A prediction that converges to a wrong point (G(x) shifted by 0.5: err rises): three predicted
  // steps without a new best err are a failure, and the relaxation makes the next step. (Shifted that
  // far, every node is across the jump: the run ends at the fixed point with all of them across.)
  const FixedPointResult misled =
      solve_fixed_point(jump_front(n,
                                   [](const Eigen::VectorXd& gx, const Eigen::VectorXd&) {
                                     return Eigen::VectorXd(gx + 0.5 * Eigen::VectorXd::Ones(gx.size()));
                                   }),
                        n, settings(FixedPointVariant::Accelerated), 1e-6);
  EXPECT_EQ(misled.status, FixedPointStatus::Converged);
  ASSERT_EQ(misled.predicted_steps, 3);
  const auto first_predicted = std::find_if(misled.history.begin(), misled.history.end(), [](const FixedPointStep& s) {
    return s.update == FixedPointUpdate::Predicted;
  });
  ASSERT_LT(first_predicted + 3, misled.history.end());
  EXPECT_EQ(first_predicted[1].update, FixedPointUpdate::Predicted);
  EXPECT_EQ(first_predicted[2].update, FixedPointUpdate::Predicted);
  EXPECT_EQ(first_predicted[3].update, FixedPointUpdate::Relaxed);
}

TEST(FixedPoint, PredictionsThatAlternateAreAveragedToTheirFixedPoint) {
  // The exact prediction E reflected, P(y) = 2E(y) − y: the same fixed point, but plain iterations
  // on P swap between two points for ever (as Coulomb's slip and pressure can make them). Averaged
  // (θ = 1/2 after the first reversal) they reach it, and the run a fixed point of G (with the jump,
  // not the plain iteration's: the averaged iterates take node 16 across, which holds itself there).
  const int n = 30;
  const SlipMap exact = jump_front(n);
  SlipMap reflected = [exact](const Eigen::VectorXd& phi, double rtol) {
    SlipEvaluation e = exact(phi, rtol);
    e.predict = [E = e.predict](const Eigen::VectorXd& y) { return Eigen::VectorXd(2 * E(y) - y); };
    return e;
  };
  const FixedPointResult plain = solve_fixed_point(exact, n, settings(FixedPointVariant::Plain), 1e-6);
  const FixedPointResult r = solve_fixed_point(reflected, n, settings(FixedPointVariant::Accelerated), 1e-6);
  ASSERT_EQ(r.status, FixedPointStatus::Converged);
  EXPECT_GE(r.predicted_steps, 1);
  EXPECT_LE(r.iterations(), 7);
  EXPECT_LT((exact(r.phi, 1e-6).slip - r.phi).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_LT(r.iterations(), plain.iterations());
}

// A map whose every QP fails.
SlipMap failing_map() {
  return [](const Eigen::VectorXd& phi, double) {
    SlipEvaluation e;
    e.slip = phi;
    e.ok = false;
    return e;
  };
}

// A QP that broke down is not told to run longer (a helper's steel-on-rubber plate under "mpgp": a
// breakdown after 212 375 iterations, and the hint said to raise solver.qp_max_iterations).
TEST(FixedPoint, ABreakdownIsNotToldToRaiseTheIterations) {
  const SlipMap broken = [](const Eigen::VectorXd& phi, double) {
    SlipEvaluation e;
    e.slip = phi;
    e.ok = false;
    e.qp_broke_down = true;
    return e;
  };
  const FixedPointResult r = solve_fixed_point(broken, 2, settings(), 1e-6);
  EXPECT_EQ(r.status, FixedPointStatus::InnerSolverFailed);
  EXPECT_NE(r.hint.find("broke down"), std::string::npos) << r.hint;
  EXPECT_EQ(r.hint.find("qp_max_iterations"), std::string::npos) << r.hint;
  const FixedPointResult limit = solve_fixed_point(failing_map(), 2, settings(), 1e-6);
  EXPECT_NE(limit.hint.find("qp_max_iterations"), std::string::npos) << limit.hint;
}

TEST(FixedPoint, InnerFailureIsNamed) {
  const SlipMap failing = failing_map();
  const FixedPointResult r = solve_fixed_point(failing, 2, settings(), 1e-6);
  EXPECT_EQ(r.status, FixedPointStatus::InnerSolverFailed);
  EXPECT_EQ(r.iterations(), 1);
  EXPECT_NE(r.hint.find("qp"), std::string::npos);
}

// The hints suggest only what applies: another QP than the one that failed (a run with solver.qp =
// "ssn" was told to try "ssn"; one with "mpgp" was told to try "ssn", which fails where MPGP alone
// does on a slender strip, not the default that solves it), and a gentler slip law only where the
// coefficient has a slope (a constant Coulomb coefficient on a nearly incompressible block was told
// "smaller friction.param").
TEST(FixedPoint, HintsSuggestOnlyWhatApplies) {
  const SlipMap failing = failing_map();
  FixedPointSettings s = settings();
  EXPECT_NE(solve_fixed_point(failing, 2, s, 1e-6).hint.find("try solver.qp = \"ssn\""), std::string::npos);
  s.hint_context.qp_is_auto = false;  // "ssn", "mpgp" or "mpgp_projcg"
  const std::string after_other = solve_fixed_point(failing, 2, s, 1e-6).hint;
  EXPECT_EQ(after_other.find("\"ssn\""), std::string::npos) << after_other;
  EXPECT_NE(after_other.find("\"auto\""), std::string::npos) << after_other;

  s = settings();
  s.max_iterations = 200;
  EXPECT_NE(solve_fixed_point(two_cycle_map(), 3, s, 1e-6).hint.find("friction.param"), std::string::npos);
  s.hint_context.slip_dependent_law = false;
  const std::string constant = solve_fixed_point(two_cycle_map(), 3, s, 1e-6).hint;
  EXPECT_NE(constant.find("does not contract"), std::string::npos) << constant;
  EXPECT_EQ(constant.find("friction.param"), std::string::npos) << constant;
  EXPECT_NE(constant.find("normal pressure"), std::string::npos) << constant;
  s.hint_context.slip_dependent_law = true;
  s.hint_context.table_law = true;  // a law by friction.points has no friction.param either
  const std::string table = solve_fixed_point(two_cycle_map(), 3, s, 1e-6).hint;
  EXPECT_EQ(table.find("friction.param"), std::string::npos) << table;
  EXPECT_NE(table.find("friction.points"), std::string::npos) << table;
}

// The tolerance of a converged run's last step, which a problem solved by one QP gets: qp_rtol_per_err
// · tol, never above qp_rtol, never below the floor (a tolerance under rounding would only run the QP
// to its iteration limit), and qp_rtol itself when the inner tolerance does not follow the outer one.
TEST(FixedPoint, FinalStepQpToleranceIsBoundedOnBothSides) {
  FixedPointSettings s;
  EXPECT_DOUBLE_EQ(final_step_qp_rtol(s, 1e-6), 1e-10);
  s.tol = 1e-9;
  EXPECT_DOUBLE_EQ(final_step_qp_rtol(s, 1e-6), s.qp_rtol_floor);
  s.tol = 0.5;
  s.qp_rtol_per_err = 0.5;
  EXPECT_DOUBLE_EQ(final_step_qp_rtol(s, 1e-6), 1e-6);
  s.qp_rtol_per_err = 0;
  EXPECT_DOUBLE_EQ(final_step_qp_rtol(s, 1e-6), 1e-6);
  s.qp_rtol_per_err = 1e-6;
  s.adaptive_qp_tolerance = false;
  EXPECT_DOUBLE_EQ(final_step_qp_rtol(s, 1e-6), 1e-6);
}

// An input that no solve can take (Coulomb's radii from an extrapolated pressure that cannot hold a
// twisted body held by contact alone): the map fails on the first input an acceleration made, which
// is not a plain iterate G(x) of the last input that solved. The run goes on from that plain iterate
// with plain steps and reaches the plain run's fixed point; a failure on a plain input still ends it.
TEST(FixedPoint, AnAcceleratedInputThatCannotBeSolvedRestartsFromThePlainStep) {
  const int n = 30;
  const SlipMap front = jump_front(n);
  struct Watch {
    Eigen::VectorXd last_plain;  // G of the last input that solved
    int failures = 0;
  };
  auto watch = std::make_shared<Watch>();
  SlipMap fails_off_the_plain_iterates = [front, watch](const Eigen::VectorXd& phi, double rtol) {
    const bool plain_input = phi.isZero(0) || (watch->last_plain.size() && phi == watch->last_plain);
    if (!plain_input && watch->failures == 0) {
      ++watch->failures;
      SlipEvaluation failed;
      failed.ok = false;
      failed.slip = phi;
      return failed;
    }
    SlipEvaluation e = front(phi, rtol);
    watch->last_plain = e.slip;
    return e;
  };
  const FixedPointResult plain = solve_fixed_point(front, n, settings(FixedPointVariant::Plain), 1e-6);
  const FixedPointResult r =
      solve_fixed_point(fails_off_the_plain_iterates, n, settings(FixedPointVariant::Accelerated), 1e-6);
  ASSERT_EQ(watch->failures, 1);
  ASSERT_EQ(r.status, FixedPointStatus::Converged);
  EXPECT_EQ(steps_made_by(r, FixedPointUpdate::Restart), 1);
  EXPECT_GT(r.plain_fallback_step, 0);
  EXPECT_LT((r.phi - plain.phi).lpNorm<Eigen::Infinity>(), 1e-12);

  // The map failing on its very first plain input: nothing to restart from.
  SlipMap fails_at_once = [front](const Eigen::VectorXd& phi, double rtol) {
    SlipEvaluation e = front(phi, rtol);
    e.ok = phi.isZero(0);
    return e;
  };
  EXPECT_EQ(solve_fixed_point(fails_at_once, n, settings(FixedPointVariant::Accelerated), 1e-6).status,
            FixedPointStatus::InnerSolverFailed);
}

}  // namespace
}  // namespace contact3d
