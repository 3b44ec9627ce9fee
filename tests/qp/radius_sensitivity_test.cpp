// RadiusSensitivity: dλ/dc at a solution of the dual QP equals the difference quotient of the
// solutions themselves, (λ(c + t dc) − λ(c − t dc)) / 2t, on random QPs with sticking, sliding and
// lifted-off cells, in double and in single precision (refined); a change of a sticking disc's
// radius does not move λ; and the same dλ/dc from the Jacobi-scaled problem through the factor of
// the whole Q (bordered_newton.hpp), in double and in single, also after the bordered solver was
// prepared for another system in between.
#include <gtest/gtest.h>

#include <optional>
#include <random>

#include <Eigen/Dense>

#include "linalg/dense_cholesky.hpp"
#include "linalg/dual_operator.hpp"
#include "linalg/symmetric_product.hpp"
#include "qp/bordered_newton.hpp"
#include "qp/jacobi_scaling.hpp"
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
  RadiusSensitivity sensitivity(a.qp, lambda, single_precision);
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
  RadiusSensitivity sensitivity(a.qp, lambda, false);
  ASSERT_TRUE(sensitivity.ok());
  EXPECT_LE(sensitivity.apply(Eigen::VectorXd::Ones(1)).norm(), 1e-12);
}

namespace {

// A QP whose solution has every cell in contact and most discs sticking: h = Q λ* for a λ* with
// positive normals and small tangents, and radii below ‖λ*_t‖ on every `sliding_every`-th cell,
// so that the border of the reduced system is small and the bordered route pays.
RandomQp mostly_sticking(int r, unsigned seed, int sliding_every) {
  RandomQp a = make_random_qp(r, true, seed);
  std::mt19937 gen(seed + 100);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  Eigen::VectorXd target(a.qp.size());
  for (int i = 0; i < r; ++i) {
    const int t1 = a.qp.layout().t1(i), t2 = a.qp.layout().t2(i);
    target[i] = 1 + uniform(gen);
    target[t1] = 0.2 * (uniform(gen) - 0.5);
    target[t2] = 0.2 * (uniform(gen) - 0.5);
    const double size = std::hypot(target[t1], target[t2]);
    a.qp.radius[i] = i % sliding_every == 0 ? 0.5 * size : 10.0;
  }
  a.qp.h = a.Q * target;
  return a;
}

std::shared_ptr<DualOperatorFactor> factor_of(const Eigen::MatrixXd& Q, bool in_single, double q_norm) {
  auto f = std::make_shared<DualOperatorFactor>();
  if (in_single) {
    f->in_single.emplace(lower_triangle_in_single(Q, q_norm));
    f->scale = q_norm;
  } else {
    f->in_double.emplace(Q);
  }
  return f;
}

}  // namespace

TEST(RadiusSensitivity, ThroughTheFactorOfQOnTheJacobiScaledProblem) {
  for (bool single : {false, true}) {
    RandomQp a = mostly_sticking(60, 21, 7);
    a.use_operator();
    const Eigen::VectorXd lambda = solve_tightly(a.qp, Eigen::VectorXd());
    const Eigen::VectorXd dc = Eigen::VectorXd::LinSpaced(a.qp.r, 1.0, -0.5);
    const Eigen::VectorXd reference = RadiusSensitivity(a.qp, lambda, false).apply(dc);
    ASSERT_GT(reference.norm(), 0);

    JacobiScaledQP jacobi(a.qp);
    BoxDiscQP scaled = jacobi.scaled(a.qp.radius);
    auto bordered = make_bordered_newton(factor_of(a.Q, single, a.qp.q_norm), jacobi.scale());
    ASSERT_TRUE(bordered);
    scaled.bordered = bordered.get();
    RadiusSensitivity sensitivity(scaled, jacobi.to_scaled(lambda), single, jacobi.scale());
    ASSERT_TRUE(sensitivity.ok());
    EXPECT_TRUE(sensitivity.through_factor_of_Q());
    const double tol = (single ? 1e-6 : 1e-9) * reference.norm();
    EXPECT_LE((sensitivity.apply(dc) - reference).norm(), tol) << (single ? "single" : "double");

    // The QP's next Newton step prepares the bordered solver for its own system: the sensitivity
    // must notice and prepare its own again.
    std::vector<Direction> other;
    for (int i = 0; i < scaled.size(); ++i) other.push_back({i, -1, 1.0, 0.0, 0.0});
    ASSERT_TRUE(bordered->prepare(other));
    EXPECT_LE((sensitivity.apply(dc) - reference).norm(), tol) << (single ? "single" : "double") << ", re-prepared";
  }
}

// With equality constraints (a body held by contact alone) the equality loop's Jacobian G D Z takes k
// reduced solves, made at once (solve_reduced_columns): through the factor of Q it is the one the
// reduced matrix's factor gives.
TEST(RadiusSensitivity, EqualityResponseThroughTheFactorOfQAsThroughTheReducedMatrix) {
  for (bool single : {false, true}) {
    RandomQp a = mostly_sticking(60, 22, 7);
    a.use_operator();
    const Eigen::VectorXd lambda = solve_tightly(a.qp, Eigen::VectorXd());
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(3, a.qp.size());
    G.row(0).head(a.qp.r).setOnes();                                                  // a lift
    G.row(1).segment(a.qp.r, a.qp.r) = Eigen::VectorXd::LinSpaced(a.qp.r, 1.0, 2.0);  // a slide
    G.row(2).head(a.qp.r) = Eigen::VectorXd::LinSpaced(a.qp.r, -1.0, 1.0);            // a tilt

    JacobiScaledQP jacobi(a.qp);
    BoxDiscQP scaled = jacobi.scaled(a.qp.radius);
    const Eigen::VectorXd start = jacobi.to_scaled(lambda);
    const std::optional<Eigen::MatrixXd> reference =
        RadiusSensitivity(scaled, start, false, jacobi.scale(), G).equality_response();
    ASSERT_TRUE(reference);
    ASSERT_GT(reference->norm(), 0);
    auto bordered = make_bordered_newton(factor_of(a.Q, single, a.qp.q_norm), jacobi.scale());
    ASSERT_TRUE(bordered);
    scaled.bordered = bordered.get();
    RadiusSensitivity sensitivity(scaled, start, single, jacobi.scale(), G);
    ASSERT_TRUE(sensitivity.through_factor_of_Q());
    const std::optional<Eigen::MatrixXd> response = sensitivity.equality_response();
    ASSERT_TRUE(response);
    EXPECT_LE((*response - *reference).norm(), (single ? 1e-6 : 1e-9) * reference->norm()) << single;
    EXPECT_LE((*response - response->transpose()).norm(), 1e-6 * response->norm());  // G D A⁻¹ Dᵀ Gᵀ
  }
}

// Matrix-free (no entries to factor): the reduced system by CG to kCgRelativeResidual, from the
// Galerkin projection onto the earlier applies' solutions. The answer is the factored one's to CG's
// tolerance; asked again for the same or a proportional change, the start is already the answer and
// CG costs only the products of its right-hand side and start residual.
TEST(RadiusSensitivity, MatrixFreeByCgRecyclingEarlierSolutions) {
  int sliding_problems = 0;
  for (unsigned seed = 1; seed <= 6; ++seed) {
    RandomQp a = make_random_qp(40, true, seed);
    a.use_operator();
    for (int i = 0; i < a.qp.r; ++i) a.qp.radius[i] = 0.3 + a.qp.radius[i];
    const Eigen::VectorXd lambda = solve_tightly(a.qp, Eigen::VectorXd());
    const Eigen::VectorXd dc = Eigen::VectorXd::LinSpaced(a.qp.r, 1.0, -0.5);
    const Eigen::VectorXd reference = RadiusSensitivity(a.qp, lambda, false).apply(dc);
    if (reference.norm() == 0) continue;  // no sliding disc
    ++sliding_problems;

    RadiusSensitivity sensitivity(contact3d::testing::matrix_free_copy(a), lambda, false);
    ASSERT_TRUE(sensitivity.ok());
    EXPECT_EQ(sensitivity.products(), 1);  // Q λ for the active sets
    EXPECT_LE((sensitivity.apply(dc) - reference).norm(), 1e-2 * reference.norm()) << "seed " << seed;
    const int first = sensitivity.products() - 1;
    EXPECT_GT(first, 3) << "seed " << seed;  // CG did work

    const int before = sensitivity.products();
    EXPECT_LE((sensitivity.apply(2 * dc) - 2 * reference).norm(), 2e-2 * reference.norm()) << "seed " << seed;
    EXPECT_LE(sensitivity.products() - before, 3) << "seed " << seed;
    EXPECT_TRUE(sensitivity.ok());
  }
  EXPECT_GE(sliding_problems, 4);
}
