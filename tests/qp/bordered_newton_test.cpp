// The Newton steps' reduced systems through a factor of the whole Q (bordered_newton.hpp): the same
// y as factoring Dᵀ Q D + diag(shift), for every kind of direction (normals in and off contact,
// discs inside, sliding and points), on the plain and the Jacobi-scaled problem, with the factor in
// double and in single precision; the cache of L⁻¹ e_i carried from one active set to the next; the
// route declined where the reduced matrix is cheaper, and taken once the factorizations it would
// have spared cost as much as its cache (ski rental); the semismooth Newton solver's answer
// unchanged by it; a factor too inaccurate to refine, whose steps preconditioned CG finishes; and,
// given Q, the switch from such a single factor to one of Q in double once its refinements cost as
// much (a good single factor kept).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <Eigen/Dense>

#include "linalg/dense_cholesky.hpp"
#include "linalg/symmetric_product.hpp"
#include "qp/bordered_newton.hpp"
#include "qp/jacobi_scaling.hpp"
#include "qp/newton_system.hpp"
#include "qp/ssn.hpp"
#include "test_support.hpp"

using namespace contact3d;

namespace {

using contact3d::testing::double_factor;
using contact3d::testing::make_random_qp;
using contact3d::testing::random_vector;
using contact3d::testing::RandomQp;

// z = λ − ρg whose active sets have most cells in contact and inside their discs, and some of each
// other kind: off contact (z_n < 0), sliding (‖z_t‖ > c); every fifth disc of make_random_qp is a point.
Eigen::VectorXd mostly_touching(const BoxDiscQP& qp, unsigned seed, double off = 0.05, double sliding = 0.05) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::VectorXd z(qp.size());
  for (int i = 0; i < qp.r; ++i) {
    z[i] = u(gen) < off ? -1 - u(gen) : 1 + u(gen);
    const double c = qp.radius[i], angle = 6.283 * u(gen);
    const double length = u(gen) < sliding ? c * (1.5 + u(gen)) : 0.8 * c * u(gen);
    z[qp.layout().t1(i)] = length * std::cos(angle);
    z[qp.layout().t2(i)] = length * std::sin(angle);
  }
  return z;
}

// make_random_qp's every fifth disc is a point (c = 0), two of them stay so here: a border of 80
// point discs of 200 would make factoring the reduced matrix the cheaper route at this size.
RandomQp few_point_discs(int r, unsigned seed, double shift = 0.05) {
  RandomQp rq = make_random_qp(r, true, seed, 3, shift);
  int points = 0;
  for (int i = 0; i < r; ++i)
    if (rq.qp.radius[i] == 0 && ++points > 2) rq.qp.radius[i] = 1;
  rq.use_operator();
  return rq;
}

// The reference: the reduced matrix factored in double.
Eigen::VectorXd reduced_solve(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::VectorXd& b) {
  Eigen::MatrixXd A;
  reduced_matrix(qp, d, A);
  const DenseCholesky chol(A);
  EXPECT_TRUE(chol.ok());
  return chol.solve(b);
}

// As the stability check makes it for large Q: the lower triangle of Q / scale in single.
std::shared_ptr<DualOperatorFactor> single_factor(const Eigen::MatrixXd& Q, double scale) {
  auto f = std::make_shared<DualOperatorFactor>();
  f->in_single.emplace(lower_triangle_in_single(Q, scale));
  f->scale = scale;
  return f;
}

}  // namespace

TEST(BorderedNewton, SolvesTheReducedSystemOfEveryKindOfDirection) {
  RandomQp rq = few_point_discs(200, 7);
  const double rho = projection_scale(rq.qp);
  const ReducedStep step = split_active_sets(rq.qp, mostly_touching(rq.qp, 3), rho);
  int off = 0, sliding = 0;
  for (const Direction& d : step.directions) sliding += d.b >= 0;
  for (int i = 0; i < rq.qp.r; ++i)
    off += step.lambda_fixed[i] == 0 &&
           std::none_of(step.directions.begin(), step.directions.end(), [&](const Direction& d) { return d.a == i; });
  ASSERT_GT(off, 3);
  ASSERT_GT(sliding, 3);
  const Eigen::VectorXd b = random_vector(static_cast<Eigen::Index>(step.directions.size()), 11);
  const Eigen::VectorXd reference = reduced_solve(rq.qp, step.directions, b);

  auto solver = make_bordered_newton(double_factor(rq.Q), Eigen::VectorXd::Ones(rq.qp.size()));
  ASSERT_TRUE(solver);
  ASSERT_TRUE(solver->prepare(step.directions));
  EXPECT_LT((solver->solve(b) - reference).norm(), 1e-10 * reference.norm());
  EXPECT_GT(solver->prepare_flops(), 0);
}

TEST(BorderedNewton, JacobiScaledProblemFromAFactorOfTheUnscaledQInSingle) {
  RandomQp rq = few_point_discs(200, 8);
  JacobiScaledQP jacobi(rq.qp);
  const BoxDiscQP& scaled = jacobi.scaled(rq.qp.radius);
  const ReducedStep step = split_active_sets(scaled, mostly_touching(scaled, 4), projection_scale(scaled));
  const Eigen::VectorXd b = random_vector(static_cast<Eigen::Index>(step.directions.size()), 12);
  const Eigen::VectorXd reference = reduced_solve(scaled, step.directions, b);

  auto in_double = make_bordered_newton(double_factor(rq.Q), jacobi.scale());
  ASSERT_TRUE(in_double && in_double->prepare(step.directions));
  EXPECT_LT((in_double->solve(b) - reference).norm(), 1e-10 * reference.norm());
  // In single precision the answer is approximate (the caller refines it): to about cond · 1e-7.
  auto in_single = make_bordered_newton(single_factor(rq.Q, rq.qp.q_norm), jacobi.scale());
  ASSERT_TRUE(in_single && in_single->prepare(step.directions));
  const double error = (in_single->solve(b) - reference).norm() / reference.norm();
  EXPECT_LT(error, 1e-2);
  EXPECT_GT(error, 0);  // it did run in single
}

// solve_columns() (the equality loop's k right-hand sides at once) gives what solve() gives for
// each column, whatever their magnitudes (each is scaled into single's range on its own), a zero
// column included; in double to rounding, in single to single's rounding of one solve.
TEST(BorderedNewton, SolvesSeveralRightHandSidesAsEachAlone) {
  RandomQp rq = few_point_discs(200, 9);
  JacobiScaledQP jacobi(rq.qp);
  const BoxDiscQP& scaled = jacobi.scaled(rq.qp.radius);
  const ReducedStep step = split_active_sets(scaled, mostly_touching(scaled, 5), projection_scale(scaled));
  const auto k = static_cast<Eigen::Index>(step.directions.size());
  Eigen::MatrixXd B(k, 4);
  B << random_vector(k, 13), 1e-30 * random_vector(k, 14), Eigen::VectorXd::Zero(k), 1e30 * random_vector(k, 15);
  for (const bool in_double : {true, false}) {
    auto solver =
        make_bordered_newton(in_double ? double_factor(rq.Q) : single_factor(rq.Q, rq.qp.q_norm), jacobi.scale());
    ASSERT_TRUE(solver && solver->prepare(step.directions));
    ASSERT_GT(solver->cached_units(), 0);  // the border's share is exercised
    const Eigen::MatrixXd Y = solver->solve_columns(B);
    ASSERT_EQ(Y.rows(), k);
    ASSERT_EQ(Y.cols(), 4);
    for (Eigen::Index j = 0; j < 4; ++j) {
      const Eigen::VectorXd alone = solver->solve(B.col(j));
      const double tolerance = in_double ? 1e-12 : 1e-5;
      EXPECT_LE((Y.col(j) - alone).norm(), tolerance * alone.norm()) << "column " << j << " double " << in_double;
    }
    EXPECT_EQ(Y.col(2).norm(), 0);
  }
}

TEST(BorderedNewton, CarriesItsCacheFromOneActiveSetToTheNext) {
  RandomQp rq = few_point_discs(200, 9);
  const double rho = projection_scale(rq.qp);
  auto solver = make_bordered_newton(double_factor(rq.Q), Eigen::VectorXd::Ones(rq.qp.size()));
  ASSERT_TRUE(solver);
  int cached_before = 0;
  for (unsigned seed : {5u, 6u, 5u}) {
    const ReducedStep step = split_active_sets(rq.qp, mostly_touching(rq.qp, seed), rho);
    const Eigen::VectorXd b = random_vector(static_cast<Eigen::Index>(step.directions.size()), seed);
    ASSERT_TRUE(solver->prepare(step.directions));
    EXPECT_LT((solver->solve(b) - reduced_solve(rq.qp, step.directions, b)).norm(), 1e-9 * b.norm());
    EXPECT_GE(solver->cached_units(), cached_before);
    if (seed == 5 && cached_before > 0) {
      EXPECT_EQ(solver->cached_units(), cached_before);  // the first active set again: nothing new to add
    }
    cached_before = solver->cached_units();
  }
}

TEST(BorderedNewton, DeclinesWhereFactoringTheReducedMatrixIsCheaper) {
  RandomQp rq = make_random_qp(200, true, 10);
  rq.use_operator();
  auto solver = make_bordered_newton(double_factor(rq.Q), Eigen::VectorXd::Ones(rq.qp.size()));
  // Most cells off contact and sliding: k small, the border large.
  const ReducedStep step = split_active_sets(rq.qp, mostly_touching(rq.qp, 3, 0.8, 0.8), projection_scale(rq.qp));
  EXPECT_FALSE(solver->prepare(step.directions));
  // No factor (the stability check's LDLᵀ path): no solver.
  EXPECT_FALSE(make_bordered_newton(nullptr, Eigen::VectorXd::Ones(rq.qp.size())));
}

TEST(BorderedNewton, BuysItsCacheOnceTheRefusedReducedFactorizationsCostAsMuch) {
  RandomQp rq = make_random_qp(200, true, 10);
  rq.use_operator();
  auto solver = make_bordered_newton(double_factor(rq.Q), Eigen::VectorXd::Ones(rq.qp.size()));
  // A border whose fill costs a few factorizations of the reduced matrix.
  const ReducedStep step = split_active_sets(rq.qp, mostly_touching(rq.qp, 3, 0.3, 0.3), projection_scale(rq.qp));
  const double k = static_cast<double>(step.directions.size()), reduced = k * k * k / 3;
  int refused = 0;
  while (!solver->prepare(step.directions) && refused < 100) ++refused;
  ASSERT_LT(refused, 100);
  EXPECT_GE(refused, 1);  // the first step factors the reduced matrix
  // Bought at the first step where the refused steps' factorizations and its own cost more than the fill.
  EXPECT_GE(solver->prepare_flops(), refused * reduced);
  EXPECT_LT(solver->prepare_flops(), (refused + 1) * reduced);
  const Eigen::VectorXd b = random_vector(static_cast<int>(k), 5);
  EXPECT_LT((solver->solve(b) - reduced_solve(rq.qp, step.directions, b)).norm(), 1e-9 * b.norm());
  // The cache bought, the same border costs only its own small factorization from then on.
  ASSERT_TRUE(solver->prepare(step.directions));
  EXPECT_LT(solver->prepare_flops(), reduced);
}

namespace {

// few_point_discs(200, 12, 0.5) with Q's single copy attached, as the QP of a large Q has it, and the
// semismooth Newton answer to 1e-10 from its reduced systems (no bordered route) as the reference.
struct WithSingleCopy {
  RandomQp rq = few_point_discs(200, 12, 0.5);
  Eigen::MatrixXf q_single = lower_triangle_in_single(rq.Q, rq.qp.q_norm);
  SsnSettings settings;
  Eigen::VectorXd reference;
  QpResult plain;
  WithSingleCopy() {
    rq.qp.Q_single = &q_single;
    rq.qp.single_scale = rq.qp.q_norm;
    settings.rtol = 1e-10;
    plain = solve_ssn(rq.qp, reference, settings);
  }
  WithSingleCopy(const WithSingleCopy&) = delete;
  WithSingleCopy& operator=(const WithSingleCopy&) = delete;
};

}  // namespace

TEST(BorderedNewton, SemismoothNewtonGivesTheSameAnswerThroughIt) {
  WithSingleCopy c;
  RandomQp& rq = c.rq;
  const SsnSettings& settings = c.settings;
  const Eigen::VectorXd& reference = c.reference;
  ASSERT_EQ(c.plain.status, QpStatus::Converged);
  Eigen::VectorXd bordered;
  auto solver = make_bordered_newton(single_factor(rq.Q, rq.qp.q_norm), Eigen::VectorXd::Ones(rq.qp.size()));
  rq.qp.bordered = solver.get();
  const QpResult through = solve_ssn(rq.qp, bordered, settings);
  ASSERT_EQ(through.status, QpStatus::Converged);
  EXPECT_GT(solver->cached_units(), 0);  // the route was taken
  EXPECT_LT((bordered - reference).norm(), 1e-8 * reference.norm());
}

// A factor too inaccurate for iterative refinement, as a single factor of an ill-conditioned Q is
// (the free thin slab asked to 1e-12): here the factor of 3Q, so that each refinement cuts the error
// by only about 2/3 and the refinement stalls. Conjugate gradients preconditioned by it finish the
// steps through the factor, with the same answer; before, every such step fell back to factoring its
// reduced system (no bordered step).
TEST(BorderedNewton, StalledRefinementIsFinishedByPreconditionedCg) {
  WithSingleCopy c;
  RandomQp& rq = c.rq;
  const SsnSettings& settings = c.settings;
  const Eigen::VectorXd& reference = c.reference;
  ASSERT_EQ(c.plain.status, QpStatus::Converged);
  EXPECT_EQ(c.plain.bordered_steps, 0);
  Eigen::VectorXd bordered;
  const Eigen::MatrixXd three_Q = 3 * rq.Q;
  auto solver = make_bordered_newton(single_factor(three_Q, 3 * rq.qp.q_norm), Eigen::VectorXd::Ones(rq.qp.size()));
  rq.qp.bordered = solver.get();
  const QpResult through = solve_ssn(rq.qp, bordered, settings);
  ASSERT_EQ(through.status, QpStatus::Converged);
  EXPECT_GT(through.bordered_steps, 0);
  EXPECT_LT((bordered - reference).norm(), 1e-8 * reference.norm());
}

namespace {

// Semismooth Newton through a single factor of `factored` (Q, or a multiple of it that stands for an
// inaccurate factor), given Q itself to switch to: whether it switched, the answer checked as above.
bool switched_solving_through(WithSingleCopy& c, double factored) {
  RandomQp& rq = c.rq;
  const Eigen::MatrixXd multiple = factored * rq.Q;
  auto solver = make_bordered_newton(single_factor(multiple, factored * rq.qp.q_norm),
                                     Eigen::VectorXd::Ones(rq.qp.size()), DenseViewPtr(&rq.Q));
  rq.qp.bordered = solver.get();
  Eigen::VectorXd bordered;
  const QpResult through = solve_ssn(rq.qp, bordered, c.settings);
  EXPECT_EQ(through.status, QpStatus::Converged);
  EXPECT_GT(through.bordered_steps, 0);
  EXPECT_LT((bordered - c.reference).norm(), 1e-8 * c.reference.norm());
  return solver->switched_to_double();
}

}  // namespace

// The factor of 3Q in single, given Q: its refinements stall (see above), and once their products
// cost as much as factoring Q in double the solver switches to that factor (its solves still refined
// by the caller, in a product or two); the answer is the same.
TEST(BorderedNewton, SwitchesToAFactorOfQInDoubleOnceStalledRefinementsCostAsMuch) {
  WithSingleCopy c;
  ASSERT_EQ(c.plain.status, QpStatus::Converged);
  EXPECT_TRUE(switched_solving_through(c, 3));
}

// A single factor of Q itself (this Q is well conditioned) refines in a step or two: never switched.
TEST(BorderedNewton, KeepsAGoodSingleFactor) {
  WithSingleCopy c;
  ASSERT_EQ(c.plain.status, QpStatus::Converged);
  EXPECT_FALSE(switched_solving_through(c, 1));
}

// The switch drops the system prepared on the single factor: preparations() moves on, so that a
// holder (RadiusSensitivity) prepares again, and the system prepared then is solved to double's rounding.
TEST(BorderedNewton, SwitchMakesHoldersPrepareAgain) {
  RandomQp rq = few_point_discs(200, 7);
  const ReducedStep step = split_active_sets(rq.qp, mostly_touching(rq.qp, 3), projection_scale(rq.qp));
  const Eigen::VectorXd b = random_vector(static_cast<int>(step.directions.size()), 4);
  auto solver =
      make_bordered_newton(single_factor(rq.Q, rq.qp.q_norm), Eigen::VectorXd::Ones(rq.qp.size()), DenseViewPtr(&rq.Q));
  ASSERT_TRUE(solver->prepare(step.directions));
  const long prepared = solver->preparations();
  solver->record_refinement(2);  // a good refinement costs nothing
  EXPECT_FALSE(solver->switched_to_double());
  solver->record_refinement(1000);
  ASSERT_TRUE(solver->switched_to_double());
  EXPECT_GT(solver->preparations(), prepared);
  ASSERT_TRUE(solver->prepare(step.directions));
  const Eigen::VectorXd reference = reduced_solve(rq.qp, step.directions, b);
  EXPECT_LT((solver->solve(b) - reference).norm(), 1e-10 * reference.norm());
}
