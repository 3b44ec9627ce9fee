// The dual QP with equality constraints Gλ = e (a body held by contact alone): a case solved by
// hand, and random QPs with friction whose answer must be the minimizer of the QP without them for
// the linear term h − Gᵀμ (checked by an independent MPGP solve) and satisfy Gλ = e.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

#include "linalg/dual_operator.hpp"
#include "qp/dual_qp_solver.hpp"
#include "qp/mpgp.hpp"
#include "test_support.hpp"

using namespace contact3d;

namespace {

QpSettings settings_for(QpVariant variant) {
  QpSettings s;
  s.variant = variant;
  return s;
}

}  // namespace

// min ½|λ|² − hᵀλ, λ >= 0, λ₁ + λ₂ + λ₃ = 2 with h = (2, 1, −5): λ = max(h − μ, 0) summing to 2
// gives μ = 0.5, λ = (1.5, 0.5, 0).
TEST(EqualityConstrainedQp, SolvedByHand) {
  const Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(3, 3);
  const Eigen::VectorXd h = (Eigen::VectorXd(3) << 2, 1, -5).finished();
  for (const QpVariant variant : {QpVariant::Auto, QpVariant::Mpgp, QpVariant::Ssn}) {
    DualQpSolver qp(Q, h, 3, false, 1.0, settings_for(variant));
    qp.set_equality(Eigen::MatrixXd::Ones(1, 3), Eigen::VectorXd::Constant(1, 2.0));
    Eigen::VectorXd lambda;
    const QpResult result = qp.solve(Eigen::VectorXd::Zero(3), lambda, 1e-12);
    ASSERT_EQ(result.status, QpStatus::Converged) << name_of(variant, kQpVariantNames);
    EXPECT_NEAR(lambda[0], 1.5, 1e-9);
    EXPECT_NEAR(lambda[1], 0.5, 1e-9);
    EXPECT_NEAR(lambda[2], 0.0, 1e-12);
    EXPECT_NEAR(qp.equality_multiplier()[0], 0.5, 1e-9);
    EXPECT_LT(qp.equality_residual(), 1e-9);
  }
}

// Random QPs with half-lines and discs, two equality rows whose right-hand side a feasible point
// meets: Gλ = e holds, and λ solves the QP without equalities for h − Gᵀμ.
TEST(EqualityConstrainedQp, RandomProblemsWithFriction) {
  std::mt19937 gen(7);
  std::normal_distribution<double> normal;
  for (unsigned seed = 1; seed <= 6; ++seed) {
    contact3d::testing::RandomQp rq = contact3d::testing::make_random_qp(8, true, seed);
    rq.use_operator();
    const int m = rq.qp.size();
    Eigen::MatrixXd G(2, m);
    for (int i = 0; i < G.rows(); ++i)
      for (int j = 0; j < m; ++j) G(i, j) = normal(gen);
    G.row(0).head(rq.qp.r).array() = G.row(0).head(rq.qp.r).array().abs() + 0.5;  // a "lift": normals push
    Eigen::VectorXd feasible = Eigen::VectorXd::Zero(m);
    feasible.head(rq.qp.r).setConstant(1.0);  // inside the half-lines, tangential parts 0
    const Eigen::VectorXd e = G * feasible;
    DualQpSolver qp(rq.Q, rq.qp.h, rq.qp.r, true, estimate_norm(rq.Q), QpSettings());
    qp.set_equality(G, e);
    Eigen::VectorXd lambda;
    const QpResult result = qp.solve(rq.qp.radius, lambda, 1e-11);
    ASSERT_EQ(result.status, QpStatus::Converged) << "seed " << seed;
    EXPECT_LT((G * lambda - e).norm(), 1e-8 * e.norm()) << "seed " << seed;
    BoxDiscQP shifted = rq.qp;
    shifted.h = rq.qp.h - G.transpose() * qp.equality_multiplier();
    Eigen::VectorXd independent = Eigen::VectorXd::Zero(m);
    MpgpSettings mpgp;
    mpgp.rtol = 1e-12;
    ASSERT_EQ(solve_mpgp(shifted, independent, mpgp).status, QpStatus::Converged);
    EXPECT_LT((lambda - independent).norm(), 1e-7 * independent.norm()) << "seed " << seed;
  }
}

// Loads the contact cannot balance (e outside what G maps the constraint set to): not converged,
// and the residual says how far off.
TEST(EqualityConstrainedQp, UnreachableRightHandSideIsReported) {
  const Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(3, 3);
  const Eigen::VectorXd h = (Eigen::VectorXd(3) << 2, 1, -5).finished();
  DualQpSolver qp(Q, h, 3, false, 1.0, QpSettings());
  qp.set_equality(Eigen::MatrixXd::Ones(1, 3), Eigen::VectorXd::Constant(1, -1.0));  // λ >= 0 cannot sum to −1
  Eigen::VectorXd lambda;
  const QpResult result = qp.solve(Eigen::VectorXd::Zero(3), lambda, 1e-10);
  EXPECT_NE(result.status, QpStatus::Converged);
  EXPECT_GT(qp.equality_residual(), 0.5);
  EXPECT_TRUE(lambda.allFinite());
}

// Slide rows alone (the in-plane motions of a symmetric body held by friction), whose loads are
// rounding, 1e-15 of the forces: balanced to the contact forces' size along them (‖G‖‖λ‖), not to their
// own, which the inner solves' rounding never reaches (a pressed shell's slide: 6.5e-9 N against
// 1e6 N, left "3.87% unbalanced" and refused before).
TEST(EqualityConstrainedQp, LoadsThatAreRoundingAreBalancedToTheContactForces) {
  std::mt19937 gen(11);
  std::normal_distribution<double> normal;
  for (unsigned seed = 1; seed <= 4; ++seed) {
    contact3d::testing::RandomQp rq = contact3d::testing::make_random_qp(8, true, seed);
    rq.use_operator();
    const int m = rq.qp.size(), r = rq.qp.r;
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(2, m);  // a slide and a turn: tangential columns only
    for (int i = 0; i < G.rows(); ++i)
      for (int j = r; j < m; ++j) G(i, j) = normal(gen);
    const Eigen::VectorXd e = Eigen::VectorXd::Constant(2, 1e-15);
    DualQpSolver qp(rq.Q, rq.qp.h, r, true, estimate_norm(rq.Q), QpSettings());
    qp.set_equality(G, e);
    Eigen::VectorXd lambda;
    ASSERT_EQ(qp.solve(rq.qp.radius, lambda, 1e-10).status, QpStatus::Converged) << "seed " << seed;
    EXPECT_LT(qp.equality_residual(), 1e-6) << "seed " << seed;
    EXPECT_LT((G * lambda - e).norm(), 1e-12 * G.norm() * lambda.norm()) << "seed " << seed;
  }
}

// One cell with friction, a lift row (its normal multiplier) and a slide row (its first tangential
// one), min ½|λ|² − hᵀλ with h = (1, 0, 0), λ₁ + μ₁ = 1 = λ_n and λ_t1 = −μ₂ inside the disc |λ_t| <= c:
// - c = 0 (a frictionless solve, Coulomb's first): no multiplier can move the slide row; the lift
//   row is solved (converged) and the slide's load stays in equality_residual() for the caller;
// - c = 1: friction holds the slide, λ_t1 = 0.3 (μ₂ = −0.3);
// - c = 0.2: the slide's load 0.3 exceeds the disc: not converged.
TEST(EqualityConstrainedQp, RowsNoMultiplierCanMoveAreLeftToTheCaller) {
  const Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(3, 3);
  const Eigen::VectorXd h = (Eigen::VectorXd(3) << 1, 0, 0).finished();
  const Eigen::MatrixXd G = (Eigen::MatrixXd(2, 3) << 1, 0, 0, 0, 1, 0).finished();
  const Eigen::VectorXd e = (Eigen::VectorXd(2) << 0.5, 0.3).finished();
  for (const QpVariant variant : {QpVariant::Auto, QpVariant::Mpgp, QpVariant::Ssn}) {
    const std::string label = name_of(variant, kQpVariantNames);
    DualQpSolver qp(Q, h, 1, true, 1.0, settings_for(variant));
    qp.set_equality(G, e);
    Eigen::VectorXd lambda;
    ASSERT_EQ(qp.solve(Eigen::VectorXd::Zero(1), lambda, 1e-12).status, QpStatus::Converged) << label;
    EXPECT_NEAR(lambda[0], 0.5, 1e-9) << label;
    EXPECT_EQ(lambda[1], 0.0) << label;
    EXPECT_NEAR(qp.equality_residual(), 0.3 / e.norm(), 1e-9) << label;

    ASSERT_EQ(qp.solve(Eigen::VectorXd::Ones(1), lambda, 1e-12).status, QpStatus::Converged) << label;
    EXPECT_NEAR(lambda[0], 0.5, 1e-9) << label;
    EXPECT_NEAR(lambda[1], 0.3, 1e-9) << label;
    EXPECT_NEAR(lambda[2], 0.0, 1e-9) << label;
    EXPECT_NEAR(qp.equality_multiplier()[1], -0.3, 1e-9) << label;
    EXPECT_LT(qp.equality_residual(), 1e-9) << label;

    EXPECT_NE(qp.solve(Eigen::VectorXd::Constant(1, 0.2), lambda, 1e-12).status, QpStatus::Converged) << label;
    EXPECT_GT(qp.equality_residual(), 0.05) << label;
    EXPECT_TRUE(lambda.allFinite()) << label;
  }
}

// dλ/dc and dμ/dc with equality constraints (radius_sensitivity.hpp: μ moves so that G dλ = 0)
// against central differences of the solutions, on random QPs whose second equality row pulls on
// the tangential multipliers (a slide held by friction): without dμ the prediction would move Gλ.
TEST(EqualityConstrainedQp, RadiusSensitivityMovesTheEqualityMultiplier) {
  std::mt19937 gen(11);
  std::normal_distribution<double> normal;
  int compared = 0;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    contact3d::testing::RandomQp rq = contact3d::testing::make_random_qp(8, true, seed);
    rq.use_operator();
    const int m = rq.qp.size(), r = rq.qp.r;
    for (int i = 0; i < r; ++i) rq.qp.radius[i] = 0.3 + rq.qp.radius[i];
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(2, m);
    G.row(0).head(r).setOnes();                                       // a lift: the normal forces' sum
    for (int i = 0; i < r; ++i) G(1, r + i) = 1 + 0.1 * normal(gen);  // a slide: the t1 forces' sum
    Eigen::VectorXd feasible = Eigen::VectorXd::Zero(m);
    feasible.head(r).setConstant(1.0);
    feasible.segment(r, r).setConstant(0.1);
    const Eigen::VectorXd e = G * feasible;
    const auto solve_at = [&](const Eigen::VectorXd& radius, Eigen::VectorXd& mu) {
      DualQpSolver qp(rq.Q, rq.qp.h, r, true, estimate_norm(rq.Q), settings_for(QpVariant::Mpgp));
      qp.set_equality(G, e);
      Eigen::VectorXd lambda;
      EXPECT_EQ(qp.solve(radius, lambda, 1e-12).status, QpStatus::Converged) << "seed " << seed;
      mu = qp.equality_multiplier();
      return lambda;
    };
    DualQpSolver qp(rq.Q, rq.qp.h, r, true, estimate_norm(rq.Q), settings_for(QpVariant::Mpgp));
    qp.set_equality(G, e);
    Eigen::VectorXd lambda;
    ASSERT_EQ(qp.solve(rq.qp.radius, lambda, 1e-12).status, QpStatus::Converged) << "seed " << seed;
    RadiusSensitivity sensitivity = qp.radius_sensitivity(lambda);
    ASSERT_TRUE(sensitivity.ok());
    const Eigen::VectorXd dc = Eigen::VectorXd::LinSpaced(r, 1.0, -0.5);
    const Eigen::VectorXd dlambda = sensitivity.apply(dc), dmu = sensitivity.equality_change();
    const double t = 1e-6;
    Eigen::VectorXd mu_plus, mu_minus;
    const Eigen::VectorXd lambda_plus = solve_at(rq.qp.radius + t * dc, mu_plus);
    const Eigen::VectorXd lambda_minus = solve_at(rq.qp.radius - t * dc, mu_minus);
    const Eigen::VectorXd quotient = (lambda_plus - lambda_minus) / (2 * t),
                          mu_quotient = (mu_plus - mu_minus) / (2 * t);
    EXPECT_LT((G * dlambda).norm(), 1e-8 * (1 + dlambda.norm())) << "seed " << seed;
    EXPECT_LE((dlambda - quotient).norm(), 1e-4 * (1 + quotient.norm())) << "seed " << seed;
    EXPECT_LE((dmu - mu_quotient).norm(), 1e-4 * (1 + mu_quotient.norm())) << "seed " << seed;
    compared += mu_quotient.norm() > 1e-2;
  }
  EXPECT_GE(compared, 4);  // μ does move with the radii in most of them
}
