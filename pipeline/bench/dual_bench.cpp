// Google Benchmark of the linear-algebra and QP fast paths on the paper brick (five-tet mesh):
// forming Q = 𝔹K⁻¹𝔹ᵀ by the reference block solves, the contact-last trailing block and the
// augmented factor (each including its factorization), and one Tresca QP by MPGP and by
// semismooth Newton. `build*/contact3d_bench`; end-to-end figures: pipeline/bench.py.
#include <map>

#include <benchmark/benchmark.h>

#include "contact/contact_face.hpp"
#include "contact/contact_operator.hpp"
#include "contact/partition.hpp"
#include "fem/assembly.hpp"
#include "fem/dof_map.hpp"
#include "linalg/dual_operator.hpp"
#include "linalg/sparse_cholesky.hpp"
#include "mesh/brick_generator.hpp"
#include "qp/mpgp.hpp"
#include "qp/ssn.hpp"

using namespace contact3d;

namespace {

struct Problem {
  Eigen::SparseMatrix<double> K, B;
  Eigen::VectorXd f;
  int r = 0;
};

Problem brick(int n) {
  const Mesh mesh = make_paper_brick({n});
  Problem p;
  const DofMap dofs = make_dof_map(mesh, {"clamped"});
  p.K = assemble_stiffness(mesh, dofs, Material{21.19e10, 0.277});
  p.f =
      assemble_load(mesh, dofs, {{"load_end", Eigen::Vector3d(1e7, 0, 2e7)}, {"load_top", Eigen::Vector3d(0, 0, -3e7)}},
                    Eigen::Vector3d::Zero());
  const ContactFace face = make_contact_face(mesh, {"contact"}, dofs);
  const Partition part = make_grid_partition(mesh, face, {2 * face.h});
  const ContactOperator op = make_contact_operator(face, part, dofs, true);
  p.B = op.B;
  p.r = op.r;
  return p;
}

const Problem& cached(int n) {
  static std::map<int, Problem> cache;
  auto it = cache.find(n);
  if (it == cache.end()) it = cache.emplace(n, brick(n)).first;
  return it->second;
}

void BM_Factorization(benchmark::State& st) {
  const Problem& p = cached(static_cast<int>(st.range(0)));
  for (auto _ : st) benchmark::DoNotOptimize(SparseCholesky(p.K).factor_nonzeros());
}
void BM_Q_BlockSolve(benchmark::State& st) {
  const Problem& p = cached(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    const SparseCholesky F(p.K);
    benchmark::DoNotOptimize(make_dual_operator(F, p.B, p.f).Q.data());
  }
}
void BM_Q_ContactLast(benchmark::State& st) {
  const Problem& p = cached(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    const SparseCholesky F(p.K, contact_dofs(p.B));
    benchmark::DoNotOptimize(make_dual_operator_schur(F, p.B, p.f).Q.data());
  }
}
void BM_Q_Augmented(benchmark::State& st) {
  const Problem& p = cached(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    SparseCholesky F(p.K, p.B);
    benchmark::DoNotOptimize(make_dual_operator_augmented(F, p.B, p.f).Q.data());
  }
}

void BM_AugmentedFactorOnly(benchmark::State& st) {
  const Problem& p = cached(static_cast<int>(st.range(0)));
  for (auto _ : st) benchmark::DoNotOptimize(SparseCholesky(p.K, p.B).factor_nonzeros());
}
void BM_AugmentedGramOnly(benchmark::State& st) {
  const Problem& p = cached(static_cast<int>(st.range(0)));
  const SparseCholesky F(p.K, p.B);
  for (auto _ : st) benchmark::DoNotOptimize(F.trailing_gram().data());
}
void BM_Solve(benchmark::State& st) {
  const Problem& p = cached(static_cast<int>(st.range(0)));
  const SparseCholesky F(p.K);
  for (auto _ : st) benchmark::DoNotOptimize(F.solve(p.f).data());
}

template <bool Ssn>
void BM_Qp(benchmark::State& st) {
  const Problem& p = cached(static_cast<int>(st.range(0)));
  static std::map<int, DualOperator> duals;
  auto it = duals.find(p.r);
  if (it == duals.end()) {
    SparseCholesky F(p.K, p.B);
    it = duals.emplace(p.r, make_dual_operator_augmented(F, p.B, p.f)).first;
  }
  BoxDiscQP qp;
  qp.Q = &it->second.Q;
  qp.h = it->second.h;
  qp.r = p.r;
  qp.radius = Eigen::VectorXd::Constant(p.r, 0.3 * 2e7);  // first Tresca step of the paper run
  qp.q_norm = 1.05 * estimate_norm(it->second.Q);
  int iterations = 0;
  for (auto _ : st) {
    Eigen::VectorXd lambda;
    if constexpr (Ssn)
      iterations = solve_ssn(qp, lambda, SsnSettings{}).iterations;
    else
      iterations = solve_mpgp(qp, lambda, MpgpSettings{}).iterations;
    benchmark::DoNotOptimize(lambda.data());
  }
  st.counters["iterations"] = iterations;
}

}  // namespace

BENCHMARK(BM_Factorization)->Arg(8)->Arg(12)->Arg(16)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Q_BlockSolve)->Arg(8)->Arg(12)->Arg(16)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Q_ContactLast)->Arg(8)->Arg(12)->Arg(16)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Q_Augmented)->Arg(8)->Arg(12)->Arg(16)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AugmentedFactorOnly)->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AugmentedGramOnly)->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Solve)->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Qp<false>)->Name("BM_Qp_Mpgp")->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Qp<true>)->Name("BM_Qp_Ssn")->Arg(8)->Arg(16)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
