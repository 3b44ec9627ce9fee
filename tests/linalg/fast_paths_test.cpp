// Fast paths against the reference paths on small problems:
// - Q from the contact-last factorization (trailing factor block + trsm/syrk) against one
//   K⁻¹ solve per row of 𝔹, on the paper brick (n = 4, 6), to 1e-10 relative;
// - the semismooth Newton QP against MPGP on small random QPs and on the brick;
// - whole solves: contactlast/ssn/inexact fixed point against blocksolve/mpgp/exact.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <string>

#include <Eigen/Dense>

#include "base/errors.hpp"

#include "contact/contact_face.hpp"
#include "contact/contact_operator.hpp"
#include "contact/partition.hpp"
#include "fem/assembly.hpp"
#include "fem/dof_map.hpp"
#include "linalg/displacement_trace.hpp"
#include "linalg/dual_operator.hpp"
#include "linalg/dual_problem.hpp"
#include "linalg/sparse_cholesky.hpp"
#include "linalg/sparse_forward_solve.hpp"
#include "mesh/brick_generator.hpp"
#include "model/contact_solver.hpp"
#include "model/scene.hpp"
#include "qp/box_disc_qp.hpp"
#include "qp/mpgp.hpp"
#include "qp/ssn.hpp"
#include "test_support.hpp"

using namespace contact3d;

namespace {

const char* const kBrick = contact3d::testing::paper_scene_text();

struct BrickData {
  Eigen::SparseMatrix<double> K, B;
  Eigen::VectorXd f;
  int r = 0;
};

BrickData brick_data(const BrickSize& size, bool friction) {
  const Scene scene = parse_scene_text(kBrick, ".", {});
  const Mesh mesh = make_paper_brick(size);
  BrickData d;
  const DofMap dofs = make_dof_map(mesh, scene.clamped);
  d.K = assemble_stiffness(mesh, dofs, scene.material);
  d.f = assemble_load(mesh, dofs, scene.tractions, scene.body_force);
  const ContactFace face = make_contact_face(mesh, scene.contact, dofs);
  const Partition part = make_grid_partition(mesh, face, {2 * face.h});
  const ContactOperator op = make_contact_operator(face, part, dofs, friction);
  d.B = op.B;
  d.r = op.r;
  return d;
}

BrickData brick_data(int n, bool friction) { return brick_data(BrickSize{n}, friction); }

void expect_same_dual(int n, bool friction) {
  const BrickData d = brick_data(n, friction);
  const SparseCholesky plain(d.K);
  const DualOperator ref = make_dual_operator(plain, d.B, d.f);
  const SparseCholesky last(d.K, contact_dofs(d.B));
  EXPECT_EQ(last.trailing_size(), static_cast<int>(contact_dofs(d.B).size()));
  const DualOperator fast = make_dual_operator_schur(last, d.B, d.f);
  ASSERT_EQ(fast.Q.rows(), ref.Q.rows());
  EXPECT_LT((fast.Q - ref.Q).norm() / ref.Q.norm(), 1e-10) << "n = " << n;
  EXPECT_LT((fast.h - ref.h).norm() / ref.h.norm(), 1e-10);
  EXPECT_LT((fast.u_free - ref.u_free).norm() / ref.u_free.norm(), 1e-10);
  EXPECT_EQ(fast.solves, 1);
  // The contact-last factor is a factorization of K: residual of a solve.
  const Eigen::VectorXd w = last.solve(d.f);
  EXPECT_LT((d.K * w - d.f).norm() / d.f.norm(), 1e-10);
  // Augmented [K 𝔹ᵀ; 𝔹 0]: Q is the Schur block captured from CHOLMOD's factorization (this
  // process's interposed dpotrf_ leaves it unfactored), and K⁻¹ goes through the leading block.
  SparseCholesky aug(d.K, d.B);
  EXPECT_TRUE(aug.augmented());
  EXPECT_TRUE(aug.captured_schur());
  const DualOperator fa = make_dual_operator_augmented(aug, d.B, d.f);
  ASSERT_TRUE(fa.Q_in_factor);  // left where the factorization put it, not copied
  EXPECT_EQ(fa.Q.size(), 0);
  EXPECT_LT((fa.Q_view() - ref.Q).norm() / ref.Q.norm(), 1e-10) << "augmented, n = " << n;
  EXPECT_EQ(fa.Q_view(), fa.Q_view().transpose());  // both triangles
  EXPECT_LT((fa.h - ref.h).norm() / ref.h.norm(), 1e-10);
  // K⁻¹ through the leading block, while the trailing one holds Q.
  const Eigen::VectorXd wa = aug.solve(d.f);
  EXPECT_TRUE(wa.allFinite());
  EXPECT_LT((d.K * wa - d.f).norm() / d.f.norm(), 1e-10);
  // L21 is the whole factor's: its Gram is Q too, and so is the old route's (σ huge, the trailing
  // block factored).
  EXPECT_LT((aug.trailing_gram() - ref.Q).norm() / ref.Q.norm(), 1e-10);
  const double sigma = 1e20 * std::max(1.0, d.B.squaredNorm()) / d.K.diagonal().maxCoeff();
  SparseCholesky whole(d.K, d.B, sigma);
  EXPECT_FALSE(whole.captured_schur());
  EXPECT_LT((make_dual_operator_augmented(whole, d.B, d.f).Q - ref.Q).norm() / ref.Q.norm(), 1e-10);
  EXPECT_LT((d.K * whole.solve(d.f) - d.f).norm() / d.f.norm(), 1e-10);
}

using contact3d::testing::RandomQp;

RandomQp random_qp(int r, bool friction, unsigned seed) {
  return contact3d::testing::make_random_qp(r, friction, seed, 4, 0.1);
}

}  // namespace

TEST(FastPaths, ContactLastSchurMatchesBlockSolves) {
  expect_same_dual(4, true);
  expect_same_dual(4, false);
  expect_same_dual(6, true);
}

TEST(FastPaths, AugmentedFactorOfAnIndefiniteKNamesK) {
  // The Schur capture falls back to the σ route only for a failure in the trailing block; a K that is
  // not positive definite is reported as such (its pivot, not the trailing block).
  BrickData d = brick_data(2, true);
  d.K.coeffRef(0, 0) = -d.K.coeff(0, 0);
  try {
    const SparseCholesky aug(d.K, d.B);
    FAIL() << "an indefinite K was factored";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("not positive definite"), std::string::npos) << what;
    EXPECT_EQ(what.find("trailing block"), std::string::npos) << what;
  }
}

TEST(FastPaths, TrailingFactorIsTheSchurComplementFactor) {
  const BrickData d = brick_data(2, true);
  const std::vector<int> t = contact_dofs(d.B);
  const SparseCholesky last(d.K, t);
  std::vector<int> order;
  const Eigen::MatrixXd L = last.trailing_factor(order);
  ASSERT_EQ(order.size(), t.size());
  // S = K_tt − K_tl K_ll⁻¹ K_lt, formed densely.
  const Eigen::MatrixXd Kd(d.K);
  std::vector<char> is_t(Kd.rows(), 0);
  for (int k : order) is_t[k] = 1;
  std::vector<int> lead;
  for (int k = 0; k < Kd.rows(); ++k)
    if (!is_t[k]) lead.push_back(k);
  const int nt = static_cast<int>(order.size()), nl = static_cast<int>(lead.size());
  Eigen::MatrixXd Ktt(nt, nt), Ktl(nt, nl), Kll(nl, nl);
  for (int i = 0; i < nt; ++i) {
    for (int j = 0; j < nt; ++j) Ktt(i, j) = Kd(order[i], order[j]);
    for (int j = 0; j < nl; ++j) Ktl(i, j) = Kd(order[i], lead[j]);
  }
  for (int i = 0; i < nl; ++i)
    for (int j = 0; j < nl; ++j) Kll(i, j) = Kd(lead[i], lead[j]);
  const Eigen::MatrixXd S = Ktt - Ktl * Kll.llt().solve(Ktl.transpose());
  EXPECT_LT((L * L.transpose() - S).norm() / S.norm(), 1e-12);
  EXPECT_TRUE(L.isLowerTriangular());
}

// Our fill-reducing ordering (nested dissection of the node quotient graph) against CHOLMOD's own
// choice: the same solutions, and no more fill on the paper brick (session 2: 10.6M against 11.9M
// nonzeros at n = 16).
TEST(FastPaths, QuotientNestedDissectionMatchesCholmodOrdering) {
  for (int n : {4, 8}) {
    const BrickData d = brick_data(n, true);
    const SparseCholesky ours(d.K), cholmod(d.K, FillOrdering::CholmodDefault);
    const Eigen::VectorXd a = ours.solve(d.f), b = cholmod.solve(d.f);
    EXPECT_LT((a - b).norm(), 1e-10 * b.norm()) << "n = " << n;
    EXPECT_LT((d.K * a - d.f).norm(), 1e-10 * d.f.norm());
    EXPECT_LE(ours.factor_nonzeros(), 1.05 * cholmod.factor_nonzeros()) << "n = " << n;
  }
}

// `contact3d check` predicts the factor a solve will form from the symbolic analysis alone: the same
// nnz(L) and flop count as the factorization's own analysis reports, for K and for the augmented
// [K 𝔹ᵀ; 𝔹 0] (whose trailing block holds Q: far more fill than K's).
TEST(FastPaths, PredictedFactorIsTheFactorFormed) {
  const BrickData d = brick_data(6, true);
  double lnz = 0, flops = 0;
  const AnalysisObserver record = [&](double nonzeros, double fl) { lnz = nonzeros, flops = fl; };
  const SparseCholesky plain(d.K, FillOrdering::QuotientNestedDissection, record);
  const FactorPrediction of_K = SparseCholesky::predict(d.K);
  EXPECT_EQ(of_K.factor_nonzeros, lnz);
  EXPECT_EQ(of_K.flops, flops);
  const SparseCholesky augmented(d.K, d.B, 0, record);
  const FactorPrediction with_multipliers = SparseCholesky::predict(d.K, &d.B);
  EXPECT_EQ(with_multipliers.factor_nonzeros, lnz);
  EXPECT_EQ(with_multipliers.flops, flops);
  const double m = static_cast<double>(d.B.rows());
  EXPECT_GT(with_multipliers.factor_nonzeros, of_K.factor_nonzeros + m * (m + 1) / 2);  // Q's block at least
}

// The distributed backend orders K from the mesh's node graph, never forming K on one process: the
// same order as from K's quotient graph (the node blocks are K's groups), also with nodes that
// keep one or two free components (a roller).
TEST(FastPaths, NodeGraphOrderIsTheQuotientOrder) {
  const Scene scene = parse_scene_text(kBrick, ".", {});
  const Mesh mesh = make_paper_brick({6});
  PrescribedDisplacement roller{"contact", {std::nullopt, std::nullopt, 0.0}};
  for (const auto& extra : {std::vector<PrescribedDisplacement>{}, std::vector<PrescribedDisplacement>{roller}}) {
    const DofMap dofs = make_dof_map(mesh, scene.clamped, extra);
    const Eigen::SparseMatrix<double> K = assemble_stiffness(mesh, dofs, scene.material);
    const NodeGraph graph = free_node_graph(mesh, dofs);
    const std::vector<int> from_graph = nested_dissection_order(graph.first_dof, graph.adj_start, graph.adj);
    EXPECT_EQ(graph.first_dof.back(), dofs.n_free);
    EXPECT_EQ(from_graph, nested_dissection_order(K)) << extra.size() << " roller groups";
  }
}

// The per-step displacement of the fixed point (a restricted back substitution through the
// augmented factor) against full K⁻¹ solves of the plain factor, for random multipliers.
TEST(FastPaths, DisplacementTraceMatchesFullSolves) {
  for (int n : {4, 6}) {
    const BrickData d = brick_data(n, true);
    const SparseCholesky plain(d.K), augmented(d.K, d.B);
    const std::vector<int> face = contact_dofs(d.B);
    const DisplacementTrace trace(augmented, d.f, face);
    // The case the trace must get right: a supernode holding both the last columns of K and the
    // first multipliers (CHOLMOD's supernode amalgamation merges them on these meshes).
    const auto L = augmented.supernodes();
    const std::int64_t first = L.n - augmented.trailing_size();
    int straddling = 0;
    for (std::int64_t s = 0; s < L.count; ++s) straddling += L.super[s] < first && L.super[s + 1] > first;
    EXPECT_GE(straddling, 1) << "n = " << n;
    EXPECT_GT(trace.work_fraction(), 0.0);
    EXPECT_LE(trace.work_fraction(), 1.0);
    std::mt19937 gen(7 + n);
    std::normal_distribution<double> normal;
    for (int trial = 0; trial < 3; ++trial) {
      Eigen::VectorXd lambda(d.B.rows());
      for (auto& v : lambda) v = 1e6 * normal(gen);
      const Eigen::VectorXd w = plain.solve(Eigen::VectorXd(d.f - d.B.transpose() * lambda));
      const Eigen::VectorXd at = trace.at(lambda), all = trace.everywhere(lambda);
      ASSERT_EQ(at.size(), static_cast<int>(face.size()));
      for (std::size_t k = 0; k < face.size(); ++k) EXPECT_NEAR(at[k], w[face[k]], 1e-10 * w.cwiseAbs().maxCoeff());
      EXPECT_LT((all - w).norm(), 1e-10 * w.norm()) << "n = " << n;
    }
  }
}

// contact.cell_size = "auto" solving again with cells of 1.5h on the factor of the 2h solve: Q, h and
// the per-step displacement of the 1.5h cells through the 2h augmented factor (forward solves of the
// new 𝔹 over its leading block) equal a fresh augmented factorization's and full solves.
TEST(FastPaths, AnotherPartitionOnTheAugmentedFactor) {
  for (int n : {4, 6}) {
    const Scene scene = parse_scene_text(kBrick, ".", {});
    const Mesh mesh = make_paper_brick(BrickSize{n});
    const DofMap dofs = make_dof_map(mesh, scene.clamped);
    const Eigen::SparseMatrix<double> K = assemble_stiffness(mesh, dofs, scene.material);
    const Eigen::VectorXd f = assemble_load(mesh, dofs, scene.tractions, scene.body_force);
    const ContactFace face = make_contact_face(mesh, scene.contact, dofs);
    const ContactOperator first =
        make_contact_operator(face, make_grid_partition(mesh, face, {2 * face.h}), dofs, true);
    const ContactOperator second =
        make_contact_operator(face, make_grid_partition(mesh, face, {1.5 * face.h}), dofs, true);
    ASSERT_GT(second.B.rows(), first.B.rows());
    const std::vector<int> face_dofs = contact_dofs(second.B);

    std::vector<std::pair<std::string, double>> seconds;
    StageClock clock(seconds, false);
    auto factored = make_cholmod_dual_problem(DualMethod::Augmented, {K, first.B, f, face_dofs}, clock);
    const std::shared_ptr<const SparseCholesky> factor = factored->factor_to_share();
    ASSERT_TRUE(factor);
    const AugmentedFactorParts parts = augmented_factor_parts(*factor);
    EXPECT_GT(parts.leading, 0.0);
    EXPECT_GT(parts.coupling, 0.0);
    const auto fresh = make_cholmod_dual_problem(DualMethod::Augmented, {K, second.B, f, face_dofs}, clock);
    const auto reused = make_dual_problem_on_factor(factor, {K, second.B, f, face_dofs}, clock);
    // The same L₁₁ up to the entries CHOLMOD's supernode amalgamation adds beside the other multipliers.
    EXPECT_NEAR(augmented_factor_parts(*fresh->factor_to_share()).leading, parts.leading, 0.05 * parts.leading);

    const Eigen::MatrixXd Q_fresh = fresh->Q(), Q_reused = reused->Q();
    ASSERT_EQ(Q_reused.rows(), second.B.rows());
    EXPECT_LT((Q_reused - Q_fresh).norm(), 1e-10 * Q_fresh.norm()) << "n = " << n;
    EXPECT_LT((Q_reused - Q_reused.transpose()).norm(), 1e-14 * Q_fresh.norm());
    EXPECT_LT((reused->h() - fresh->h()).norm(), 1e-10 * fresh->h().norm());
    const SparseCholesky plain(K);
    std::mt19937 gen(11 + n);
    std::normal_distribution<double> normal;
    Eigen::VectorXd lambda(second.B.rows());
    for (auto& v : lambda) v = 1e6 * normal(gen);
    const Eigen::VectorXd w = plain.solve(Eigen::VectorXd(f - second.B.transpose() * lambda));
    const Eigen::VectorXd at = reused->face_displacement(lambda), all = reused->displacement(lambda);
    for (std::size_t k = 0; k < face_dofs.size(); ++k)
      EXPECT_NEAR(at[static_cast<Eigen::Index>(k)], w[face_dofs[k]], 1e-10 * w.cwiseAbs().maxCoeff());
    EXPECT_LT((all - w).norm(), 1e-10 * w.norm());
    EXPECT_LT(reused->step_solve_fraction, 1.0);
  }
}

TEST(FastPaths, SsnMatchesMpgpOnRandomQps) {
  int newton_only = 0;
  for (unsigned seed = 1; seed <= 30; ++seed) {
    for (bool friction : {true, false}) {
      RandomQp a = random_qp(4 + seed % 9, friction, seed);
      a.qp.Q = &a.Q;
      a.qp.q_norm = 1.05 * estimate_norm(a.Q);
      Eigen::VectorXd l_mpgp, l_ssn;
      MpgpSettings ms;
      ms.rtol = 1e-10;
      const QpResult rm = solve_mpgp(a.qp, l_mpgp, ms);
      SsnSettings ss;
      ss.rtol = 1e-10;
      const QpResult rs = solve_ssn(a.qp, l_ssn, ss);
      ASSERT_EQ(rm.status, QpStatus::Converged);
      ASSERT_EQ(rs.status, QpStatus::Converged) << "seed " << seed;
      EXPECT_TRUE(is_feasible(a.qp, l_ssn));
      EXPECT_LT((l_ssn - l_mpgp).norm(), 1e-7 * (1 + l_mpgp.norm())) << "seed " << seed;
      if (rs.cg_steps + rs.expansion_steps + rs.proportioning_steps == 0) ++newton_only;
    }
  }
  EXPECT_GE(newton_only, 50);  // of 60: Newton itself converges, the MPGP fallback is rare
}

TEST(FastPaths, SsnLapackPathMatchesMpgp) {  // m >= 400 takes the LAPACK branch
  RandomQp a = random_qp(150, true, 7);
  a.qp.Q = &a.Q;
  a.qp.q_norm = 1.05 * estimate_norm(a.Q);
  Eigen::VectorXd l_mpgp, l_ssn;
  MpgpSettings ms;
  ms.rtol = 1e-10;
  ASSERT_EQ(solve_mpgp(a.qp, l_mpgp, ms).status, QpStatus::Converged);
  SsnSettings ss;
  ss.rtol = 1e-10;
  const QpResult rs = solve_ssn(a.qp, l_ssn, ss);
  ASSERT_EQ(rs.status, QpStatus::Converged);
  EXPECT_EQ(rs.cg_steps + rs.expansion_steps + rs.proportioning_steps, 0);
  EXPECT_LT((l_ssn - l_mpgp).norm(), 1e-7 * (1 + l_mpgp.norm()));
}

TEST(FastPaths, SsnMatchesMpgpOnTheBrick) {
  const BrickData d = brick_data(4, true);
  const SparseCholesky K(d.K);
  const DualOperator dual = make_dual_operator(K, d.B, d.f);
  BoxDiscQP qp;
  qp.Q = &dual.Q;
  qp.h = dual.h;
  qp.r = d.r;
  qp.radius.resize(d.r);  // radii c = F g with a mix of the two friction levels
  for (int i = 0; i < d.r; ++i) qp.radius[i] = (i % 3 == 0 ? 0.3 : 0.2) * 2e7;
  qp.q_norm = 1.05 * estimate_norm(dual.Q);
  Eigen::VectorXd l_mpgp, l_ssn;
  MpgpSettings ms;
  ms.rtol = 1e-9;
  ASSERT_EQ(solve_mpgp(qp, l_mpgp, ms).status, QpStatus::Converged);
  SsnSettings ss;
  ss.rtol = 1e-9;
  const QpResult rs = solve_ssn(qp, l_ssn, ss);
  ASSERT_EQ(rs.status, QpStatus::Converged);
  // Newton finishes on its own (at most a few MPGP fallback steps: the exact count depends on rounding,
  // e.g. under sanitizer builds one step was seen).
  EXPECT_LE(rs.cg_steps + rs.expansion_steps + rs.proportioning_steps, 10);
  EXPECT_LE(rs.iterations, 20);
  EXPECT_LT((l_ssn - l_mpgp).norm() / l_mpgp.norm(), 1e-6);
}

TEST(FastPaths, WholeSolvesAgreeAcrossVariants) {
  const Scene ref_scene = parse_scene_text(kBrick, ".", {"solver.schur=\"blocksolve\"", "solver.qp=\"mpgp\""});
  const Mesh mesh = make_paper_brick({4});
  const SolveResult ref = solve_scene(ref_scene, mesh);
  ASSERT_TRUE(ref.converged);
  EXPECT_EQ(ref.schur_method, "blocksolve");
  const std::vector<std::vector<std::string>> variants = {
      {"solver.schur=\"contactlast\""},    {"solver.schur=\"contactlast\"", "solver.qp=\"ssn\""},
      {"solver.schur=\"augmented\""},      {"solver.qp=\"ssn\"", "solver.inexact_fixed_point=true"},
      {"solver.fixed_point=\"anderson\""},
  };
  for (const auto& v : variants) {
    const Scene scene = parse_scene_text(kBrick, ".", v);
    const SolveResult res = solve_scene(scene, mesh);
    ASSERT_TRUE(res.converged) << v.back();
    // Fixed-point tolerance 1e-4 bounds how far two converged runs can sit apart.
    EXPECT_LT((res.u - ref.u).norm() / ref.u.norm(), 1e-4) << v.back();
    EXPECT_LT((res.lambda - ref.lambda).norm() / ref.lambda.norm(), 1e-3) << v.back();
  }
  // Same fixed point and same QP: the fast dual changes nothing but rounding.
  const SolveResult cl =
      solve_scene(parse_scene_text(kBrick, ".", {"solver.schur=\"contactlast\"", "solver.qp=\"mpgp\""}), mesh);
  EXPECT_EQ(cl.schur_method, "contactlast");
  EXPECT_EQ(cl.fixed_point.iterations(), ref.fixed_point.iterations());
  EXPECT_LT((cl.u - ref.u).norm() / ref.u.norm(), 1e-8);
}

// The matrix-free dual (Q never formed): its products, diagonal and h are the dense Q's, and a whole
// solve with the same QP (MPGP) takes the same fixed-point and QP iterations to the same answer.
TEST(FastPaths, MatrixFreeDualIsTheDenseOne) {
  const BrickData d = brick_data(4, true);
  const SparseCholesky plain(d.K);
  const DualOperator ref = make_dual_operator(plain, d.B, d.f);
  // 𝔹's rows forward-solved: kept in supernodal blocks (Q = WᵀW, its diagonal and products without
  // forming it), or streamed for the diagonal alone.
  const Eigen::SparseMatrix<double> Bt = d.B.transpose();
  const ForwardSolvedBlocks kept = forward_solve_by_supernodes(plain, Bt);
  EXPECT_EQ(kept.entries(), forward_solved_block_entries(plain, Bt));
  EXPECT_LT(kept.entries(), static_cast<std::int64_t>(Bt.rows()) * Bt.cols() / 2);  // a cell's rows stop at the top
  const Eigen::MatrixXd V = Eigen::MatrixXd::Random(ref.Q.rows(), 3);
  EXPECT_LT((kept.gram_product(V) - ref.Q * V).norm() / (ref.Q * V).norm(), 1e-12);
  EXPECT_LT((kept.gram_product(V.col(1)) - ref.Q * V.col(1)).norm() / (ref.Q * V.col(1)).norm(), 1e-12);
  for (const Eigen::VectorXd& diagonal : {kept.column_squared_norms(), forward_solved_diagonal(plain, d.B, 16)})
    EXPECT_LT((diagonal - ref.Q.diagonal()).norm() / ref.Q.diagonal().norm(), 1e-12);
  StageTimes times;
  StageClock clock(times);
  const DualProblemInput input{d.K, d.B, d.f, {}};
  const std::unique_ptr<DualProblem> dual = make_cholmod_dual_problem(DualMethod::MatrixFree, input, clock);
  EXPECT_FALSE(dual->forms_Q());
  EXPECT_EQ(dual->method, "matrix_free");
  EXPECT_LT((dual->h() - ref.h).norm() / ref.h.norm(), 1e-12);
  const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(ref.Q.rows(), -1.0, 2.0);
  EXPECT_LT((dual->apply_Q(v) - ref.Q * v).norm() / (ref.Q * v).norm(), 1e-12);
  EXPECT_LT((dual->Q_diagonal() - ref.Q.diagonal()).norm() / ref.Q.diagonal().norm(), 1e-12);

  const Mesh mesh = make_paper_brick({4});
  const SolveResult dense = solve_scene(parse_scene_text(kBrick, ".", {"solver.qp=\"mpgp\""}), mesh);
  for (const char* qp : {"mpgp", "auto", "ssn"}) {
    const std::string variant = std::string("solver.qp=\"") + qp + "\"";
    const SolveResult free =
        solve_scene(parse_scene_text(kBrick, ".", {"solver.schur=\"matrix_free\"", variant}), mesh);
    ASSERT_TRUE(free.converged) << qp;
    EXPECT_EQ(free.schur_method, "matrix_free");
    EXPECT_EQ(free.qp_method, qp);
    EXPECT_EQ(free.fixed_point.iterations(), dense.fixed_point.iterations()) << qp;
    if (std::string(qp) == "mpgp") {
      EXPECT_EQ(free.n_mult, dense.n_mult);  // the same algorithm, the same products
    }
    if (std::string(qp) == "ssn") {
      EXPECT_GT(free.qp_newton_steps, 0);  // Newton steps, their systems by CG
    }
    EXPECT_EQ(free.fixed_point.newton_steps + free.fixed_point.predicted_steps, 0) << qp;
    // The same algorithm as the dense run to rounding; Newton steps stop elsewhere within the QP's
    // tolerance (2e-8 measured).
    EXPECT_LT((free.u - dense.u).norm() / dense.u.norm(), std::string(qp) == "mpgp" ? 1e-8 : 1e-7) << qp;
    // cond(Q) from 40 Lanczos steps on 36 multipliers against the dense check's (power iteration and
    // the factor of Q): both estimates, a fraction of a per cent apart.
    EXPECT_NEAR(free.stability_condition / dense.stability_condition, 1.0, 0.01) << qp;
  }
  // Coulomb's bound on the matrix-free dual: the same answer as on the dense one, to the fixed
  // point's tolerance (1e-4; the dense run takes predicted steps, the matrix-free one cannot).
  const std::vector<std::string> coulomb = {"friction.model=\"coulomb\"", "friction.slip_bound=0",
                                            "solver.qp=\"mpgp\""};
  std::vector<std::string> coulomb_free = coulomb;
  coulomb_free.push_back("solver.schur=\"matrix_free\"");
  const SolveResult c_dense = solve_scene(parse_scene_text(kBrick, ".", coulomb), mesh);
  const SolveResult c_free = solve_scene(parse_scene_text(kBrick, ".", coulomb_free), mesh);
  ASSERT_TRUE(c_free.converged);
  EXPECT_LT((c_free.u - c_dense.u).norm() / c_dense.u.norm(), 1e-4);
}

TEST(FastPaths, LanczosBracketsTheSpectrumFromInside) {
  std::mt19937 random(7);
  std::normal_distribution<double> normal;
  const int n = 120;
  const Eigen::MatrixXd G = Eigen::MatrixXd::NullaryExpr(n, n, [&] { return normal(random); });
  const Eigen::MatrixXd A = G * G.transpose() / n + 1e-3 * Eigen::MatrixXd::Identity(n, n);
  const Eigen::VectorXd exact = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues();
  const auto product = [&A](const Eigen::VectorXd& v) { return Eigen::VectorXd(A * v); };
  const SpectrumEstimate few = lanczos_extremes(n, product, 40);
  EXPECT_EQ(few.products, 40);
  EXPECT_LE(few.largest, exact.maxCoeff() * (1 + 1e-12));
  EXPECT_GT(few.largest, 0.99 * exact.maxCoeff());
  EXPECT_GE(few.smallest, exact.minCoeff() * (1 - 1e-12));
  const SpectrumEstimate all = lanczos_extremes(n, product, n);  // a full Krylov space: exact
  EXPECT_NEAR(all.largest, exact.maxCoeff(), 1e-9 * exact.maxCoeff());
  EXPECT_NEAR(all.smallest, exact.minCoeff(), 1e-6 * exact.minCoeff());
}

// estimate_norm stops its Lanczos steps once the top Ritz pair's residual is 1e-3 of it: on a
// spectrum like a dual operator's (a few large eigenvalues above a continuum) within 1e-3 from below
// in far fewer than its 50 products, and on a clustered top (a slow power iteration) still within it.
TEST(FastPaths, NormEstimateStopsOnceTheTopRitzPairHasConverged) {
  std::mt19937 random(11);
  std::normal_distribution<double> normal;
  const int n = 400;
  const Eigen::MatrixXd G = Eigen::MatrixXd::NullaryExpr(n, n, [&] { return normal(random); });
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(G);
  const Eigen::MatrixXd U = qr.householderQ();
  for (const double top_gap : {0.5, 1e-3}) {
    Eigen::VectorXd spectrum = Eigen::VectorXd::LinSpaced(n, 1e-4, 1.0);
    spectrum[n - 1] = 10.0;
    spectrum[n - 2] = 10.0 * (1 - top_gap);
    const Eigen::MatrixXd A = U * spectrum.asDiagonal() * U.transpose();
    int products = 0;
    const double estimate = estimate_norm(n, [&](const Eigen::VectorXd& v) {
      ++products;
      return Eigen::VectorXd(A * v);
    });
    EXPECT_LE(estimate, 10.0 * (1 + 1e-12)) << top_gap;
    EXPECT_GT(estimate, 10.0 * (1 - 2e-3)) << top_gap;
    EXPECT_LT(products, 50) << top_gap;
  }
}

TEST(FastPaths, FrictionlessIsOneQpWithoutFixedPoint) {
  const Scene scene = parse_scene_text(kBrick, ".", {"friction.slip_bound=0.0", "solver.qp=\"ssn\""});
  const SolveResult res = solve_scene(scene, make_paper_brick({4}));
  ASSERT_TRUE(res.converged);
  EXPECT_EQ(res.fixed_point.iterations(), 0);
  EXPECT_EQ(res.n_dual, res.n_cells);
}

TEST(FastPaths, ConstantLawIsOneTrescaSolve) {
  const Scene scene = parse_scene_text(kBrick, ".", {"friction.law=\"constant\"", "friction.value=0.3"});
  const SolveResult res = solve_scene(scene, make_paper_brick({4}));
  ASSERT_TRUE(res.converged);
  EXPECT_EQ(res.fixed_point.iterations(), 0);
  EXPECT_EQ(res.steps.size(), 1u);
  EXPECT_EQ(res.n_dual, 3 * res.n_cells);
}

TEST(FastPaths, NoContactIsOneLinearSolve) {
  const Scene scene = parse_scene_text(kBrick, ".", {"boundary.contact=[]"});
  const SolveResult res = solve_scene(scene, make_paper_brick({4}));
  ASSERT_TRUE(res.converged);
  EXPECT_EQ(res.n_mult, 1);
  EXPECT_EQ(res.n_dual, 0);
  EXPECT_LT(res.kkt.equilibrium, 1e-10);
}

// Single-precision products on the matrix-free dual: none before prepare_single_products, and none
// where W is kept (the paper's brick: its products already read less than a solve). Where products
// go through solves the float factor serves them (check_matrix_free_bodies.py: the thin slab).
TEST(FastPaths, MatrixFreeSingleProductsOnlyWhereProductsSolve) {
  const BrickData d = brick_data(4, true);
  StageTimes times;
  StageClock clock(times);
  const DualProblemInput input{d.K, d.B, d.f, {}};
  const std::unique_ptr<DualProblem> dual = make_cholmod_dual_problem(DualMethod::MatrixFree, input, clock);
  ASSERT_FALSE(dual->blocks_pay());  // W kept
  const Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(dual->size(), -1.0, 2.0);
  EXPECT_FALSE(dual->prepare_single_products(std::numeric_limits<double>::infinity()));
  EXPECT_EQ(dual->apply_Q_single(v), dual->apply_Q(v));
}
