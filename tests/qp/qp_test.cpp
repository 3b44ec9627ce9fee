// MPGP on small random QPs with both constraint kinds, checked against the KKT conditions
// directly and against an independent brute-force solver (projected gradient, many steps).
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

#include "linalg/dual_operator.hpp"
#include "qp/box_disc_qp.hpp"
#include "qp/jacobi_scaling.hpp"
#include "qp/mpgp.hpp"
#include "test_support.hpp"

using namespace contact3d;

namespace {

using contact3d::testing::make_random_qp;
using contact3d::testing::RandomQp;

// Brute force: projected gradient with a fixed step 1/‖Q‖, run to stagnation.
Eigen::VectorXd brute_force(const BoxDiscQP& qp) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(qp.size());
  const double step = 1.0 / (*qp.Q).operatorNorm();
  for (int k = 0; k < 400000; ++k) {
    Eigen::VectorXd y = x - step * (*qp.Q * x - qp.h);
    project(qp, y);
    if ((y - x).norm() < 1e-14 * (1 + x.norm())) return y;
    x = y;
  }
  return x;
}

// Largest violation of the KKT conditions, relative to ‖h‖.
double kkt_violation(const BoxDiscQP& qp, const Eigen::VectorXd& x) {
  const Eigen::VectorXd g = *qp.Q * x - qp.h;
  const int r = qp.r;
  double worst = 0;
  for (int i = 0; i < r; ++i) {
    worst = std::max(worst, -x[i]);
    worst = std::max(worst, x[i] > 1e-10 ? std::abs(g[i]) : std::max(0.0, -g[i]));
  }
  if (qp.with_friction)
    for (int i = 0; i < r; ++i) {
      const Eigen::Vector2d lt(x[r + i], x[2 * r + i]), gt(g[r + i], g[2 * r + i]);
      const double c = qp.radius[i];
      worst = std::max(worst, lt.norm() - c);
      if (c == 0) continue;
      if (lt.norm() < c * (1 - 1e-9))
        worst = std::max(worst, gt.norm());
      else
        worst = std::max(worst, (gt + gt.norm() * lt / lt.norm()).norm());  // −g points outward along λ_t
    }
  return worst / qp.h.norm();
}

class MpgpRandom : public ::testing::TestWithParam<std::tuple<int, bool, ExpansionKind>> {};

TEST_P(MpgpRandom, MatchesKktAndBruteForce) {
  const auto [r, friction, expansion] = GetParam();
  for (unsigned seed = 1; seed <= 6; ++seed) {
    RandomQp rq = make_random_qp(r, friction, seed * 7919 + r);
    rq.use_operator();
    MpgpSettings settings;
    settings.rtol = 1e-10;
    settings.expansion = expansion;
    Eigen::VectorXd x;
    const QpResult res = solve_mpgp(rq.qp, x, settings);
    ASSERT_EQ(res.status, QpStatus::Converged) << "seed " << seed;
    EXPECT_TRUE(is_feasible(rq.qp, x, 1e-12));
    EXPECT_LT(kkt_violation(rq.qp, x), 1e-7) << "seed " << seed;
    const Eigen::VectorXd ref = brute_force(rq.qp);
    EXPECT_LT((x - ref).norm(), 1e-6 * (1 + ref.norm())) << "seed " << seed;
    EXPECT_LE(rq.qp.value(x), rq.qp.value(ref) + 1e-9 * std::abs(rq.qp.value(ref)));
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, MpgpRandom,
                         ::testing::Combine(::testing::Values(3, 8, 20), ::testing::Bool(),
                                            ::testing::Values(ExpansionKind::FullGradient, ExpansionKind::FreeGradient,
                                                              ExpansionKind::ProjectedCG)));

TEST(BoxDiscSet, ProjectionAndSteps) {
  Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(3, 3);
  BoxDiscQP qp;
  qp.Q = &Q;
  qp.r = 1;
  qp.h = Eigen::VectorXd::Zero(3);
  qp.radius = Eigen::VectorXd::Constant(1, 2.0);
  Eigen::VectorXd x(3);
  x << -1, 3, 4;
  project(qp, x);
  EXPECT_DOUBLE_EQ(x[0], 0);
  EXPECT_NEAR(x[1], 1.2, 1e-15);
  EXPECT_NEAR(x[2], 1.6, 1e-15);
  Eigen::VectorXd y(3), p(3);
  y << 1, 0, 0;
  p << 0.5, -1, 0;  // λ − a p: normal hits 0 at a = 2, disc boundary at a = 2
  EXPECT_NEAR(max_feasible_step(qp, y, p), 2.0, 1e-14);
  p << 0.25, -1, 0;
  EXPECT_NEAR(max_feasible_step(qp, y, p), 2.0, 1e-14);
  p << 1, -1, 0;
  EXPECT_NEAR(max_feasible_step(qp, y, p), 1.0, 1e-14);
}

TEST(Mpgp, ZeroRightHandSideGivesZero) {
  Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(3, 3);
  BoxDiscQP qp;
  qp.Q = &Q;
  qp.r = 1;
  qp.h = Eigen::VectorXd::Zero(3);
  qp.radius = Eigen::VectorXd::Constant(1, 1.0);
  qp.q_norm = 1;
  Eigen::VectorXd x = Eigen::VectorXd::Constant(3, 0.3);
  EXPECT_EQ(solve_mpgp(qp, x, {}).status, QpStatus::Converged);
  EXPECT_EQ(x.norm(), 0.0);
}

}  // namespace

// The Jacobi-scaled problem has the same minimiser (mapped back), with badly scaled cells.
TEST(JacobiScaling, SameMinimiserOnBadlyScaledQps) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    RandomQp rq = make_random_qp(6, true, seed);
    // Scale cell sizes over four orders of magnitude: Q → D Q D, h → D h, radii stay.
    Eigen::VectorXd d(18);
    for (int i = 0; i < 6; ++i) d[i] = d[6 + i] = d[12 + i] = std::pow(10.0, i % 4 - 2);
    rq.Q = d.asDiagonal() * rq.Q * d.asDiagonal();
    rq.qp.h = d.cwiseProduct(rq.qp.h);
    rq.qp.Q = &rq.Q;
    rq.qp.q_norm = 1.05 * estimate_norm(rq.Q, 300);
    JacobiScaledQP scaled(rq.qp);
    const BoxDiscQP& sq = scaled.scaled(rq.qp.radius);
    MpgpSettings settings;
    settings.rtol = 1e-12;
    Eigen::VectorXd mu;
    ASSERT_EQ(solve_mpgp(sq, mu, settings).status, QpStatus::Converged);
    const Eigen::VectorXd x = scaled.from_scaled(mu);
    EXPECT_TRUE(is_feasible(rq.qp, x, 1e-12));
    EXPECT_LT(kkt_violation(rq.qp, x), 1e-8) << "seed " << seed;
  }
}
