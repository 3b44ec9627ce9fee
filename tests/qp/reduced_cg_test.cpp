// Newton steps without Q's entries (qp/reduced_cg.hpp, the matrix-free dual's Newton steps): CG on
// the reduced system gives what a dense factorization of it gives, from zero or from a start, and
// stops at its product budget; semismooth Newton and the hybrid on a matrix-free QP (Q only as a
// product) reach MPGP's minimiser.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include <Eigen/Dense>

#include "linalg/dual_operator.hpp"
#include "qp/hybrid_qp.hpp"
#include "qp/mpgp.hpp"
#include "qp/newton_system.hpp"
#include "qp/reduced_cg.hpp"
#include "qp/ssn.hpp"
#include "test_support.hpp"

using namespace contact3d;
using contact3d::testing::make_random_qp;
using contact3d::testing::matrix_free_copy;
using contact3d::testing::RandomQp;

namespace {

// A Newton step's reduced system on the QP `a` (the active sets of a scaled h) with its answer by a
// dense factorization.
struct ReducedSystem {
  ReducedStep step;
  Eigen::VectorXd b, exact;
  Eigen::MatrixXd A;  // lower triangle
};
ReducedSystem reduced_system(const RandomQp& a) {
  ReducedSystem s;
  const Eigen::VectorXd z = 1.5 * a.qp.h / a.Q.diagonal().mean();
  s.step = split_active_sets(a.qp, z, projection_scale(a.qp));
  s.b = restrict_to(s.step.directions, a.qp.h - a.Q * s.step.lambda_fixed);
  reduced_matrix(a.qp, s.step.directions, s.A);
  s.exact = s.A.selfadjointView<Eigen::Lower>().llt().solve(s.b);
  return s;
}

}  // namespace

TEST(ReducedCg, SolvesTheReducedSystemAsItsFactorizationDoes) {
  int sliding = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    RandomQp a = make_random_qp(12, true, seed);
    a.qp.Q = &a.Q;
    const BoxDiscQP free = matrix_free_copy(a);
    // Active sets of some z: normals in and out of contact, tangents inside and outside their discs.
    const Eigen::VectorXd z = 1.5 * a.qp.h / a.Q.diagonal().mean();
    const double rho = projection_scale(a.qp);
    const ReducedStep step = split_active_sets(a.qp, z, rho);
    for (const Direction& d : step.directions) sliding += d.b >= 0;
    ASSERT_FALSE(step.directions.empty());
    const Eigen::VectorXd b = restrict_to(step.directions, a.qp.h - a.Q * step.lambda_fixed);
    Eigen::MatrixXd A;
    reduced_matrix(a.qp, step.directions, A);
    const Eigen::VectorXd exact = A.selfadjointView<Eigen::Lower>().llt().solve(b);

    Eigen::VectorXd y;  // from zero
    const ReducedCgResult cg = solve_reduced_cg(free, step.directions, b, 1e-12 * b.norm(), 1000, y);
    EXPECT_TRUE(cg.converged) << "seed " << seed;
    EXPECT_LE(cg.iterations, 2 * static_cast<int>(b.size())) << "seed " << seed;
    EXPECT_LT((y - exact).norm(), 1e-9 * exact.norm()) << "seed " << seed;

    Eigen::VectorXd from_solution = exact;  // a start at the solution costs its one residual product
    const ReducedCgResult warm = solve_reduced_cg(free, step.directions, b, 1e-8 * b.norm(), 1000, from_solution);
    EXPECT_TRUE(warm.converged);
    EXPECT_EQ(warm.iterations, 1);

    Eigen::VectorXd capped;  // the budget is a hard stop, reported as not converged
    const ReducedCgResult short_run = solve_reduced_cg(free, step.directions, b, 1e-14 * b.norm(), 2, capped);
    EXPECT_FALSE(short_run.converged);
    EXPECT_EQ(short_run.iterations, 2);
    EXPECT_LT((capped - exact).norm(), exact.norm());  // CG's iterates approach the solution in A's norm
  }
  EXPECT_GT(sliding, 0);  // the two-weight (sliding) directions were exercised
}

TEST(ReducedCg, NewtonOnAMatrixFreeQpReachesMpgpsMinimiser) {
  int newton_steps = 0;
  for (unsigned seed = 1; seed <= 12; ++seed)
    for (bool friction : {true, false}) {
      RandomQp a = make_random_qp(6 + static_cast<int>(seed) % 9, friction, seed);
      a.qp.Q = &a.Q;
      a.qp.q_norm = 1.05 * estimate_norm(a.Q);
      Eigen::VectorXd reference;
      MpgpSettings ms;
      ms.rtol = 1e-10;
      ASSERT_EQ(solve_mpgp(a.qp, reference, ms).status, QpStatus::Converged);
      const BoxDiscQP free = matrix_free_copy(a);

      Eigen::VectorXd by_ssn;
      SsnSettings ss;
      ss.rtol = 1e-10;
      const QpResult rs = solve_ssn(free, by_ssn, ss);
      EXPECT_EQ(rs.status, QpStatus::Converged) << "seed " << seed;
      EXPECT_TRUE(is_feasible(free, by_ssn));
      EXPECT_LT((by_ssn - reference).norm(), 1e-7 * (1 + reference.norm())) << "seed " << seed;
      newton_steps += rs.newton_steps;

      Eigen::VectorXd by_hybrid;
      HybridSettings hs;
      hs.rtol = 1e-10;
      hs.window = 1;  // every round hands over to Newton steps (no cap on rounds without Q's entries)
      const QpResult rh = solve_hybrid(free, by_hybrid, hs);
      EXPECT_EQ(rh.status, QpStatus::Converged) << "seed " << seed;
      EXPECT_LT((by_hybrid - reference).norm(), 1e-7 * (1 + reference.norm())) << "seed " << seed;
    }
  EXPECT_GT(newton_steps, 0);
}

// The two-level preconditioner (BoxDiscQP::coarse_group): on an operator whose diagonally scaled
// spectrum is spread by a few strong smooth modes (as a thin plate's bending spreads Q's), CG
// deflating the groups' indicators needs far fewer products than CG with the diagonal alone, to the
// same answer; a second step with the same directions reuses the coarse products (none recomputed),
// and one with a direction changed recomputes only its group's column.
TEST(ReducedCg, TwoLevelDeflatesTheSmoothModes) {
  const int r = 60, m = 3 * r, per_group = 6, groups_per_component = r / per_group;
  RandomQp a = make_random_qp(r, true, 3, 3 * r, 0.0);  // a well-conditioned local part
  // A smooth kernel on each component's line of cells (the compliance of a plate under smooth loads).
  Eigen::MatrixXd smooth = Eigen::MatrixXd::Zero(m, m);
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < r; ++j) smooth(c * r + i, c * r + j) = std::exp(-std::pow((i - j) / (0.25 * r), 2));
  a.Q = (a.Q / a.Q.diagonal().mean() + 1e3 * smooth).eval();
  a.qp.Q = &a.Q;
  BoxDiscQP free = matrix_free_copy(a);
  const ReducedSystem system = reduced_system(a);
  const ReducedStep& step = system.step;
  const Eigen::VectorXd& b = system.b;
  const Eigen::VectorXd& exact = system.exact;
  const double tol = 1e-10 * b.norm();

  Eigen::VectorXd by_diagonal;
  const ReducedCgResult plain = solve_reduced_cg(free, step.directions, b, tol, 5000, by_diagonal);
  ASSERT_TRUE(plain.converged);

  for (int i = 0; i < m; ++i) free.coarse_group.push_back((i / r) * groups_per_component + (i % r) / per_group);
  const Eigen::MatrixXd* Q = &a.Q;
  int block_columns = 0;
  free.block_product = [Q, &block_columns](const Eigen::MatrixXd& V) {
    block_columns += static_cast<int>(V.cols());
    return Eigen::MatrixXd(*Q * V);
  };
  free.coarse_products = std::make_shared<CoarseProducts>();
  Eigen::VectorXd by_two_level;
  const ReducedCgResult deflated = solve_reduced_cg(free, step.directions, b, tol, 5000, by_two_level);
  ASSERT_TRUE(deflated.converged);
  EXPECT_LT((by_two_level - exact).norm(), 1e-8 * exact.norm());
  EXPECT_LT((by_diagonal - exact).norm(), 1e-8 * exact.norm());
  const int coarse_columns = block_columns;
  EXPECT_GT(coarse_columns, 0);
  EXPECT_LE(coarse_columns, 3 * groups_per_component);
  EXPECT_LT(deflated.iterations - coarse_columns, plain.iterations / 3)
      << "diagonal " << plain.iterations << ", two-level " << deflated.iterations << " (" << coarse_columns
      << " coarse)";

  Eigen::VectorXd again;  // the same directions: the coarse products are reused
  const ReducedCgResult reused = solve_reduced_cg(free, step.directions, b, tol, 5000, again);
  EXPECT_EQ(block_columns, coarse_columns);
  EXPECT_EQ(reused.iterations, deflated.iterations - coarse_columns);
  EXPECT_EQ(deflated.coarse_products, coarse_columns);
  EXPECT_EQ(reused.coarse_products, 0);
  EXPECT_LT((again - exact).norm(), 1e-8 * exact.norm());

  std::vector<Direction> changed = step.directions;  // one direction's weight changed: one group recomputed
  changed.front().w_a *= 0.5;
  Eigen::VectorXd y;
  solve_reduced_cg(free, changed, restrict_to(changed, a.qp.h), tol, 5000, y);
  EXPECT_EQ(block_columns, coarse_columns + 1);
}

// Single-precision products (BoxDiscQP::single_product; here Q in float) in the Newton steps' CG:
// taken where the tolerance asks to cut the start's residual by at most kSingleCgReduction, to the
// answer within that tolerance; not taken where it asks for more, nor where the problem has none.
// The two-level preconditioner's coarse products go through single_block_product either way.
TEST(ReducedCg, SingleProductsWhereTheToleranceAllowsThem) {
  RandomQp a = make_random_qp(40, true, 5);
  a.qp.Q = &a.Q;
  BoxDiscQP free = matrix_free_copy(a);
  const Eigen::MatrixXf Q_float = a.Q.cast<float>();
  int single_columns = 0;
  free.single_product = [&Q_float](const Eigen::VectorXd& v) {
    return Eigen::VectorXd((Q_float * v.cast<float>()).cast<double>());
  };
  free.single_block_product = [&Q_float, &single_columns](const Eigen::MatrixXd& V) {
    single_columns += static_cast<int>(V.cols());
    return Eigen::MatrixXd((Q_float * V.cast<float>()).cast<double>());
  };
  const ReducedSystem system = reduced_system(a);
  const ReducedStep& step = system.step;
  const Eigen::VectorXd& b = system.b;
  const Eigen::VectorXd& exact = system.exact;
  const Eigen::MatrixXd& A = system.A;

  // From zero the start's residual is ‖b‖: a loose tolerance takes single products and meets it
  // (the true residual, in double, within twice the tolerance).
  const double loose = 1e-3 * b.norm();
  Eigen::VectorXd y;
  const ReducedCgResult single = solve_reduced_cg(free, step.directions, b, loose, 1000, y);
  ASSERT_TRUE(single.converged);
  EXPECT_EQ(single.single_products, single.iterations);
  EXPECT_LT((b - A.selfadjointView<Eigen::Lower>() * y).norm(), 2 * loose);
  // A tight one stays in double and reaches the answer to it.
  Eigen::VectorXd tight_y;
  const ReducedCgResult tight = solve_reduced_cg(free, step.directions, b, 1e-12 * b.norm(), 1000, tight_y);
  ASSERT_TRUE(tight.converged);
  EXPECT_EQ(tight.single_products, 0);
  EXPECT_LT((tight_y - exact).norm(), 1e-9 * exact.norm());
  // Without single products nothing changes.
  const BoxDiscQP plain = matrix_free_copy(a);
  Eigen::VectorXd plain_y;
  EXPECT_EQ(solve_reduced_cg(plain, step.directions, b, loose, 1000, plain_y).single_products, 0);

  // The coarse products in float: the preconditioner only, the answer as tight as in double.
  for (int i = 0; i < free.size(); ++i) free.coarse_group.push_back(i / 10);
  free.block_product = [&a](const Eigen::MatrixXd& V) { return Eigen::MatrixXd(a.Q * V); };
  Eigen::VectorXd deflated_y;
  const ReducedCgResult deflated = solve_reduced_cg(free, step.directions, b, 1e-12 * b.norm(), 1000, deflated_y);
  ASSERT_TRUE(deflated.converged);
  EXPECT_GT(single_columns, 0);
  EXPECT_EQ(single_columns, deflated.coarse_products);
  EXPECT_LT((deflated_y - exact).norm(), 1e-9 * exact.norm());
}
