// MPGP and semismooth Newton with a single-precision copy of Q (mpgp.hpp, ssn.hpp): the answer must meet
// the tolerance on a gradient computed in double, however far below single precision the tolerance is.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "linalg/dual_operator.hpp"
#include "qp/box_disc_qp.hpp"
#include "qp/dual_qp_solver.hpp"
#include "qp/mpgp.hpp"
#include "qp/ssn.hpp"
#include "test_support.hpp"

using namespace contact3d;

namespace {

using contact3d::testing::make_random_qp;
using contact3d::testing::RandomQp;

// The single copy as DualQpSolver makes it: the lower triangle of Q / ‖Q‖.
struct SingleCopy {
  Eigen::MatrixXf Q;
  double scale;
  explicit SingleCopy(const Eigen::MatrixXd& Qd) : Q((Qd / Qd.norm()).cast<float>()), scale(Qd.norm()) {}
  void attach(BoxDiscQP& qp) const {
    qp.Q_single = &Q;
    qp.single_scale = scale;
  }
};

// ‖gᴾ(λ)‖ / ‖h‖ from a gradient computed here, in double.
double exact_projected_gradient(const BoxDiscQP& qp, const Eigen::VectorXd& x) {
  const GradientSplit s = split_gradient(qp, x, *qp.Q * x - qp.h);
  return std::sqrt(s.free.squaredNorm() + s.chopped.squaredNorm()) / qp.h.norm();
}

// Q with eigenvalues spread over `condition` (random eigenvectors).
Eigen::MatrixXd with_condition(int m, double condition, unsigned seed) {
  const RandomQp base = make_random_qp(m, false, seed);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(base.Q);
  const Eigen::MatrixXd V = qr.householderQ();
  Eigen::VectorXd eig(m);
  for (int i = 0; i < m; ++i) eig[i] = std::pow(condition, -double(i) / (m - 1));
  return V * eig.asDiagonal() * V.transpose();
}

}  // namespace

TEST(SinglePrecisionProducts, MpgpMeetsADoubleToleranceOnRandomQps) {
  for (const ExpansionKind expansion :
       {ExpansionKind::FullGradient, ExpansionKind::FreeGradient, ExpansionKind::ProjectedCG}) {
    for (unsigned seed = 1; seed <= 4; ++seed) {
      RandomQp rq = make_random_qp(20, true, seed * 31);
      rq.use_operator();
      MpgpSettings settings;
      settings.rtol = 1e-10;
      settings.expansion = expansion;
      Eigen::VectorXd reference;
      ASSERT_EQ(solve_mpgp(rq.qp, reference, settings).status, QpStatus::Converged);
      const SingleCopy single(rq.Q);
      single.attach(rq.qp);
      Eigen::VectorXd x;
      const QpResult res = solve_mpgp(rq.qp, x, settings);
      ASSERT_EQ(res.status, QpStatus::Converged) << "seed " << seed;
      EXPECT_GT(res.single_products, 0);
      EXPECT_TRUE(is_feasible(rq.qp, x, 1e-12));
      EXPECT_LE(exact_projected_gradient(rq.qp, x), 1e-10) << "seed " << seed;
      EXPECT_LT((x - reference).norm(), 1e-7 * (1 + reference.norm())) << "seed " << seed;
    }
  }
}

// MpgpSettings::single_products = false (the equality loop's tight inner solves) keeps every product in
// double although the problem has a single copy.
TEST(SinglePrecisionProducts, CanBeTurnedOffPerSolve) {
  RandomQp rq = make_random_qp(20, true, 7);
  rq.use_operator();
  const SingleCopy single(rq.Q);
  single.attach(rq.qp);
  MpgpSettings settings;
  settings.rtol = 1e-10;
  Eigen::VectorXd with_single, in_double;
  EXPECT_GT(solve_mpgp(rq.qp, with_single, settings).single_products, 0);
  settings.single_products = false;
  const QpResult res = solve_mpgp(rq.qp, in_double, settings);
  ASSERT_EQ(res.status, QpStatus::Converged);
  EXPECT_EQ(res.single_products, 0);
  EXPECT_LE(exact_projected_gradient(rq.qp, in_double), 1e-10);
}

// cond(Q) = 1e6 and a tolerance of 1e-9: single-precision rounding sits far above it, so the
// recursive gradient claims convergence where the exact one does not; the solve must go on (in
// double, after kSingleFalseStops refusals) until the exact one does.
TEST(SinglePrecisionProducts, StopsOnlyWhenTheExactGradientMeetsTheTolerance) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    RandomQp rq = make_random_qp(30, false, seed);
    rq.Q = with_condition(30, 1e6, seed);
    rq.use_operator();
    const SingleCopy single(rq.Q);
    single.attach(rq.qp);
    MpgpSettings settings;
    settings.rtol = 1e-9;
    Eigen::VectorXd x;
    const QpResult res = solve_mpgp(rq.qp, x, settings);
    ASSERT_EQ(res.status, QpStatus::Converged) << "seed " << seed;
    EXPECT_LE(exact_projected_gradient(rq.qp, x), 1e-9) << "seed " << seed;
    EXPECT_LE(res.projected_gradient, 1e-9);
  }
}

TEST(SinglePrecisionProducts, AutoUsesThemFromTheThresholdOn) {
  EXPECT_FALSE(uses_single_products(QpPrecision::Auto, kMixedPrecisionMinSize - 1));
  EXPECT_TRUE(uses_single_products(QpPrecision::Auto, kMixedPrecisionMinSize));
  EXPECT_FALSE(uses_single_products(QpPrecision::Double, 10 * kMixedPrecisionMinSize));
  EXPECT_TRUE(uses_single_products(QpPrecision::Mixed, 3));
}

// Semismooth Newton with a single copy of Q solves its reduced systems in single precision refined in
// double: the same answer as in double, to the same exact tolerance, and the refinement's products
// are counted.
TEST(SinglePrecisionProducts, NewtonStepsRefinedToTheDoubleAnswer) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    RandomQp rq = make_random_qp(40, true, seed * 13);
    rq.use_operator();
    SsnSettings settings;
    settings.rtol = 1e-11;
    Eigen::VectorXd reference;
    const QpResult in_double = solve_ssn(rq.qp, reference, settings);
    ASSERT_EQ(in_double.status, QpStatus::Converged);
    const SingleCopy single(rq.Q);
    single.attach(rq.qp);
    Eigen::VectorXd x;
    const QpResult mixed = solve_ssn(rq.qp, x, settings);
    ASSERT_EQ(mixed.status, QpStatus::Converged) << "seed " << seed;
    EXPECT_LE(exact_projected_gradient(rq.qp, x), 1e-11) << "seed " << seed;
    EXPECT_LT((x - reference).norm(), 1e-8 * (1 + reference.norm())) << "seed " << seed;
    EXPECT_GT(mixed.hessian_products, in_double.hessian_products) << "no refinement products: not solved in single";
  }
}

// Tolerances far below the refinement's usual 1e-10 (the equality loop of a body held by contact
// alone solves to 1e-12): the single-precision Newton steps are refined to the QP's tolerance, so
// semismooth Newton gets there in about the steps it takes in double, without MPGP's help, on a Q
// whose eigenvalues spread over 1e6.
TEST(SinglePrecisionProducts, NewtonStepsRefinedToATightTolerance) {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    RandomQp rq = make_random_qp(60, true, seed * 17);
    rq.Q = with_condition(static_cast<int>(rq.Q.rows()), 1e6, seed * 17);
    rq.use_operator();
    SsnSettings settings;
    settings.rtol = 1e-13;
    settings.fallback_to_mpgp = false;
    Eigen::VectorXd reference;
    const QpResult in_double = solve_ssn(rq.qp, reference, settings);
    ASSERT_EQ(in_double.status, QpStatus::Converged) << "seed " << seed;
    const SingleCopy single(rq.Q);
    single.attach(rq.qp);
    Eigen::VectorXd x;
    const QpResult mixed = solve_ssn(rq.qp, x, settings);
    ASSERT_EQ(mixed.status, QpStatus::Converged) << "seed " << seed;
    EXPECT_LE(exact_projected_gradient(rq.qp, x), 1e-13) << "seed " << seed;
    EXPECT_LE(mixed.newton_steps, in_double.newton_steps + 2) << "seed " << seed;
  }
}

// The matrix-free solver (a Q seen only through products, as on the matrix-free dual) takes the
// single products it is given (MatrixFreeQ::single_product: a float factor of K there, Q in float
// here) where QpSettings::precision asks for them, in MPGP and in the Newton steps' CG, and meets the
// tolerance on the exact gradient all the same; with "double" it leaves them unused.
TEST(SinglePrecisionProducts, MatrixFreeSolverTakesThemWhereAsked) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const RandomQp rq = make_random_qp(60, true, seed * 7);
    const Eigen::MatrixXf Q_float = rq.Q.cast<float>();
    const auto make_q = [&] {
      MatrixFreeQ q;
      q.product = [&rq](const Eigen::VectorXd& v) { return Eigen::VectorXd(rq.Q * v); };
      q.single_product = [&Q_float](const Eigen::VectorXd& v) {
        return Eigen::VectorXd((Q_float * v.cast<float>()).cast<double>());
      };
      q.diagonal = rq.Q.diagonal();
      return q;
    };
    QpResult results[2];
    Eigen::VectorXd answers[2];
    for (int mixed = 0; mixed < 2; ++mixed) {
      QpSettings settings;
      settings.precision = mixed ? QpPrecision::Mixed : QpPrecision::Double;
      DualQpSolver solver(make_q(), rq.qp.h, rq.qp.r, true, estimate_norm(rq.Q), settings);
      results[mixed] = solver.solve(rq.qp.radius, answers[mixed], 1e-10);
      ASSERT_EQ(results[mixed].status, QpStatus::Converged) << "seed " << seed;
    }
    EXPECT_EQ(results[0].single_products, 0);
    EXPECT_GT(results[1].single_products, 0) << "seed " << seed;
    BoxDiscQP check = rq.qp;
    check.Q = &rq.Q;
    EXPECT_LE(exact_projected_gradient(check, answers[1]), 1e-10) << "seed " << seed;
    EXPECT_LT((answers[1] - answers[0]).norm(), 1e-7 * (1 + answers[0].norm())) << "seed " << seed;
  }
}
