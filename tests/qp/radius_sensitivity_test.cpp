// RadiusSensitivity: dλ/dc at a solution of the dual QP equals the difference quotient of the
// solutions themselves, (λ(c + t dc) − λ(c − t dc)) / 2t, on random QPs with sticking, sliding and
// lifted-off cells, in double and in single precision (refined); and a change of a sticking disc's
// radius does not move λ.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "linalg/dual_operator.hpp"
#include "qp/mpgp.hpp"
#include "qp/radius_sensitivity.hpp"
#include "test_support.hpp"

using namespace contact3d;
using contact3d::testing::make_random_qp;
using contact3d::testing::RandomQp;

namespace {

Eigen::VectorXd solve_tightly(const BoxDiscQP& qp, Eigen::VectorXd start) {
  MpgpSettings ms;
  ms.rtol = 1e-13;
  ms.max_iterations = 1000000;
  EXPECT_EQ(solve_mpgp(qp, start, ms).status, QpStatus::Converged);
  return start;
}

struct Comparison {
  double error = 0, size = 0;
  int sliding = 0;
};

// The derivative against central differences of the QP's solutions for a random dc.
Comparison compare(unsigned seed, bool single_precision) {
  RandomQp a = make_random_qp(6, true, seed);
  a.use_operator();
  // Positive radii (no point discs), so that every disc can slide.
  for (int i = 0; i < a.qp.r; ++i) a.qp.radius[i] = 0.3 + a.qp.radius[i];
  const Eigen::VectorXd lambda = solve_tightly(a.qp, Eigen::VectorXd());
  Comparison out;
  for (int i = 0; i < a.qp.r; ++i)
    out.sliding +=
        std::abs(std::hypot(lambda[a.qp.layout().t1(i)], lambda[a.qp.layout().t2(i)]) - a.qp.radius[i]) < 1e-9;
  const Eigen::VectorXd dc = Eigen::VectorXd::LinSpaced(a.qp.r, 1.0, -0.5);
  const RadiusSensitivity sensitivity(a.qp, lambda, single_precision);
  EXPECT_TRUE(sensitivity.ok());
  const Eigen::VectorXd derivative = sensitivity.apply(dc);
  const double t = 1e-6;
  BoxDiscQP plus = a.qp, minus = a.qp;
  plus.radius += t * dc;
  minus.radius -= t * dc;
  const Eigen::VectorXd quotient = (solve_tightly(plus, lambda) - solve_tightly(minus, lambda)) / (2 * t);
  out.error = (derivative - quotient).norm();
  out.size = quotient.norm();
  return out;
}

}  // namespace

TEST(RadiusSensitivity, MatchesTheDifferenceQuotientOfTheSolutions) {
  int with_sliding = 0;
  for (unsigned seed = 1; seed <= 12; ++seed)
    for (bool single : {false, true}) {
      const Comparison c = compare(seed, single);
      with_sliding += c.sliding > 0;
      EXPECT_LE(c.error, 1e-5 * (1 + c.size)) << "seed " << seed << (single ? " single" : " double");
    }
  EXPECT_GT(with_sliding, 12);  // most problems have sliding discs, where dλ/dc is not zero
}

TEST(RadiusSensitivity, StickingDiscsDoNotMove) {
  // One cell, λ_t strictly inside its disc: the radius is not active and λ does not depend on it.
  RandomQp a = make_random_qp(1, true, 3);
  a.use_operator();
  a.qp.radius[0] = 1e6;
  const Eigen::VectorXd lambda = solve_tightly(a.qp, Eigen::VectorXd());
  const RadiusSensitivity sensitivity(a.qp, lambda, false);
  ASSERT_TRUE(sensitivity.ok());
  EXPECT_LE(sensitivity.apply(Eigen::VectorXd::Ones(1)).norm(), 1e-12);
}
