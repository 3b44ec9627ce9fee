// The feasible descent step of the semismooth Newton solver (qp/ssn.hpp), taken where backtracking
// on ‖F‖ finds no step: which unknowns fix_early_exits fixes, and a QP of the kind that needs it — the
// dual of a slender cantilever lying on the plane it is clamped level with, pressed at its far end
// (pipeline/scenes/strip.toml in one dimension): cond(Q) grows like n⁴, and every cell but the loaded
// ones touches with λ = 0 and a zero gap (degenerate). (The strip itself: ctest
// strip_fixed_point_stops_on_a_solved_step.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "qp/hybrid_qp.hpp"
#include "qp/mpgp.hpp"
#include "qp/newton_system.hpp"
#include "qp/ssn.hpp"
#include "test_support.hpp"

using namespace contact3d;

namespace {

// The compliance of a cantilever x ∈ (0, 1] at x_i = i/n, clamped at x = 0: bending (EI = 1)
// C_ij = a² (3b − a) / 6, a = min(x_i, x_j), b = max; or axial (EA = 1) C_ij = a.
Eigen::MatrixXd cantilever_compliance(int n, bool bending) {
  Eigen::MatrixXd C(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double a = (std::min(i, j) + 1.0) / n, b = (std::max(i, j) + 1.0) / n;
      C(i, j) = bending ? a * a * (3 * b - a) / 6 : a;
    }
  return C;
}

// The cantilever's contact QP, Jacobi-scaled as the solver scales Q: the nodes x > 0.9 pushed down by
// 1 each onto the plane the clamp is level with (h = C f) and, with friction, pulled along the beam by
// 0.2 each (radii 0.5 there, 0.1 elsewhere: they stick). The solution λ = f (in the scaled unknowns:
// f / s) leaves the beam flat, with a zero gap and no slip at every node.
struct Cantilever {
  Eigen::MatrixXd Q;
  BoxDiscQP qp;
  Eigen::VectorXd solution;
};
Cantilever pressed_cantilever(int n, bool friction) {
  const int m = friction ? 3 * n : n;
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(m, m);
  C.topLeftCorner(n, n) = cantilever_compliance(n, true);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(m);
  Cantilever c;
  c.qp.r = n;
  c.qp.with_friction = friction;
  if (friction) {
    C.block(n, n, n, n) = cantilever_compliance(n, false);         // along the beam
    C.block(2 * n, 2 * n, n, n) = cantilever_compliance(n, true);  // across it, in the plane
    c.qp.radius = Eigen::VectorXd::Constant(n, 0.1);
  }
  for (int i = 0; i < n; ++i) {
    if ((i + 1.0) / n <= 0.9) continue;
    f[i] = 1;
    if (!friction) continue;
    f[n + i] = 0.2;
    c.qp.radius[i] = 0.5;
  }
  const Eigen::VectorXd s = C.diagonal().cwiseSqrt().cwiseInverse();
  c.Q = s.asDiagonal() * C * s.asDiagonal();
  c.qp.h = s.asDiagonal() * (C * f);
  c.solution = f.cwiseQuotient(s);
  c.qp.Q = &c.Q;
  c.qp.q_norm = 1.05 * estimate_norm(c.Q, 200);
  return c;
}

}  // namespace

TEST(FeasibleStep, FixesTheUnknownsThatLeaveBeforeHalfTheStep) {
  // Three cells with friction, layout [λ_n | λ_t1 | λ_t2]; every unknown free.
  BoxDiscQP qp;
  qp.r = 3;
  qp.with_friction = true;
  qp.radius = Eigen::VectorXd::Constant(3, 1.0);
  ReducedStep step{Eigen::VectorXd::Zero(9), {}};
  for (int a = 0; a < 9; ++a) step.directions.push_back({a, -1, 1.0, 0.0, 0.0});
  Eigen::VectorXd lambda(9), target(9);
  //          normals             t1                t2
  lambda << 0.001, 1.0, 0.5, /**/ 0.9, 0.0, 0.0, /**/ 0.0, 0.2, 0.0;
  target << -1.0, -0.1, 2.0, /**/ 2.0, 0.0, 0.0, /**/ 0.0, 3.0, 0.5;
  const EarlyExits exits = fix_early_exits(qp, lambda, target, 0.5, step);
  // Normal 0 crosses zero at 0.001/1.001 of the step: fixed at 0. Normal 1 at 1/1.1 (late): kept, and
  // the first exit. Disc 0 reaches its circle at 0.1/1.1: fixed there, at (1, 0). Disc 1 at about 0.29
  // (from (0, 0.2) to (0, 3)): fixed at (0, 1). Disc 2 stays inside.
  EXPECT_EQ(exits.fixed, 3);
  EXPECT_NEAR(exits.first_exit, 1.0 / 1.1, 1e-15);
  std::vector<int> free_units;
  for (const Direction& d : step.directions) free_units.push_back(d.a);
  EXPECT_EQ(free_units, (std::vector<int>{1, 2, 5, 8}));
  EXPECT_EQ(step.lambda_fixed[0], 0.0);
  EXPECT_NEAR(step.lambda_fixed[3], 1.0, 1e-15);
  EXPECT_EQ(step.lambda_fixed[6], 0.0);
  EXPECT_NEAR(step.lambda_fixed[7], 1.0, 1e-15);
  EXPECT_EQ(step.lambda_fixed[4], 0.0);
}

TEST(FeasibleStep, NoExitsLeaveTheStepAsItWas) {
  BoxDiscQP qp;
  qp.r = 2;
  qp.with_friction = false;
  ReducedStep step{Eigen::VectorXd::Zero(2), {{0, -1, 1.0, 0.0, 0.0}, {1, -1, 1.0, 0.0, 0.0}}};
  const EarlyExits exits = fix_early_exits(qp, Eigen::Vector2d(1.0, 0.5), Eigen::Vector2d(2.0, 0.1), 0.5, step);
  EXPECT_EQ(exits.fixed, 0);
  EXPECT_EQ(exits.first_exit, 1.0);
  EXPECT_EQ(step.directions.size(), 2u);
}

TEST(FeasibleStep, SlenderCantileverReachesItsFlatSolution) {
  // n = 800: cond(Q) about 1e11. Feasible steps are taken (the Newton targets leave the half-lines
  // by far at the degenerate nodes), and the answer is the flat beam's, within what cond(Q) · rtol allows.
  // With friction whether a Newton target leaves the set depends on rounding (none did on one machine's
  // OpenBLAS kernels, where another took them): there only the answer is checked.
  for (bool friction : {false, true}) {
    Cantilever c = pressed_cantilever(800, friction);
    for (bool hybrid : {true, false}) {
      Eigen::VectorXd lambda;
      QpResult r;
      if (hybrid) {
        HybridSettings hs;
        hs.rtol = 1e-10;
        r = solve_hybrid(c.qp, lambda, hs);
      } else {
        SsnSettings ss;
        ss.rtol = 1e-10;
        r = solve_ssn(c.qp, lambda, ss);
      }
      const std::string what = std::string(hybrid ? "hybrid" : "ssn") + (friction ? ", friction" : "");
      ASSERT_EQ(r.status, QpStatus::Converged) << what;
      if (!friction) { EXPECT_GE(r.feasible_steps, 1) << what; }
      EXPECT_LE(r.feasible_steps, r.newton_steps) << what;
      EXPECT_LE(r.projected_gradient, 1e-10) << what;
      EXPECT_TRUE(is_feasible(c.qp, lambda)) << what;
      EXPECT_LT((lambda - c.solution).norm(), 1e-3 * c.solution.norm()) << what;
    }
  }
}
