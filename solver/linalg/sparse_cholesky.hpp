// SparseCholesky: one CHOLMOD supernodal factorization P K Pᵀ = L Lᵀ (fill-reducing ordering
// below), reused for every application of K⁻¹. Owns its cholmod_common: no global
// state; not copyable.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "linalg/dense_view.hpp"

namespace contact3d {

// Fill-reducing orderings: CHOLMOD's own choice on K (cholmod_analyze: AMD, then METIS when AMD
// fills too much; the yardstick of the benchmarks), or nested dissection of K's quotient graph
// (one vertex per mesh node; what every other constructor uses).
enum class FillOrdering { CholmodDefault, QuotientNestedDissection };

// Called between the symbolic analysis and the numeric factorization with the nnz(L) and flop
// count CHOLMOD predicts: progress lines, and a memory check before the long part. May throw.
using AnalysisObserver = std::function<void(double factor_nonzeros, double flops)>;

// The order every constructor below factors K in (nested dissection of K's quotient graph; K with
// both triangles stored): order[k] is the dof pivoted k-th. For other solvers of K (MUMPS).
std::vector<int> nested_dissection_order(const Eigen::SparseMatrix<double>& K);
// The same from the graph of K's node blocks, for a K never formed on one process (the distributed
// backend): vertex v holds dofs first_dof[v] .. first_dof[v + 1] − 1 and is adjacent to
// adj[adj_start[v] .. adj_start[v + 1]) (sorted; see fem's free_node_graph).
std::vector<int> nested_dissection_order(const std::vector<int>& first_dof, const std::vector<int>& adj_start,
                                         const std::vector<int>& adj);

// The size and flop count of a factorization, as CHOLMOD's symbolic analysis predicts them.
struct FactorPrediction {
  double factor_nonzeros = 0;  // nnz(L)
  double flops = 0;
};

class SparseCholesky {
 public:
  // Analyze + factorize. Throws std::runtime_error if K is not positive definite (e.g. the
  // clamped part Γu is empty or does not prevent rigid motions).
  explicit SparseCholesky(const Eigen::SparseMatrix<double>& K,
                          FillOrdering ordering = FillOrdering::QuotientNestedDissection,
                          const AnalysisObserver& observe = {});
  // Same factorization with the dofs `trailing` ordered last (nested dissection on the others): the trailing diagonal
  // block L_tt of the factor then satisfies L_tt L_ttᵀ = S, the Schur complement of K onto those dofs, and (K⁻¹)_tt =
  // S⁻¹.
  SparseCholesky(const Eigen::SparseMatrix<double>& K, const std::vector<int>& trailing,
                 const AnalysisObserver& observe = {});
  // Factor of the augmented matrix [K 𝔹ᵀ; 𝔹 σI] with the rows of 𝔹 ordered last (nested dissection
  // on K's dofs). Its leading block is a Cholesky factor of K — solve() applies K⁻¹ through it —
  // and its off-diagonal block L_21 = 𝔹 (L_11)⁻ᵀ gives 𝔹K⁻¹𝔹ᵀ = L_21 L_21ᵀ (trailing_gram()).
  // σ = 0 (the default): the trailing block, −𝔹K⁻¹𝔹ᵀ after CHOLMOD's updates, is captured before it
  // would be factored (schur_capture.hpp) and turned in place into 𝔹K⁻¹𝔹ᵀ (schur_block()): the
  // factor's trailing block is then not a factor, which only the trailing rows of a solve see (they
  // are discarded, see solve()). σ > 0, or where the capture does not work: [K 𝔹ᵀ; 𝔹 σI] factored
  // whole, σ huge (‖𝔹‖_F² / max diag K · 1e20 when 0 was asked) so that it is positive definite;
  // σ never enters L_21, so it costs no accuracy, only the trailing block's factorization.
  SparseCholesky(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>& B, double sigma = 0,
                 const AnalysisObserver& observe = {});
  // What factoring K (the first constructor, nested dissection), or the augmented [K 𝔹ᵀ; 𝔹 σI] when B
  // is given (the constructor above), would take, from the symbolic analysis alone (no numeric
  // factorization): the figures an AnalysisObserver receives, for `contact3d check`.
  static FactorPrediction predict(const Eigen::SparseMatrix<double>& K, const Eigen::SparseMatrix<double>* B = nullptr);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // Several right-hand sides at once (dense, BLAS-3 in CHOLMOD).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B) const;
  // Half a solve, L⁻¹P B (not for the augmented factor): the squared norm of column j is
  // B_jᵀ K⁻¹ B_j, since K⁻¹ = Pᵀ L⁻ᵀ L⁻¹ P.
  Eigen::MatrixXd forward_solve(const Eigen::MatrixXd& B) const;

  // Dense lower-triangular L_tt (only for the `trailing` constructor). `order[k]` is the dof
  // (row of K) of row/column k of L_tt.
  Eigen::MatrixXd trailing_factor(std::vector<int>& order) const;
  int trailing_size() const { return n_trailing_; }
  // G = L_t,lead L_t,leadᵀ: the rows of the factor in the trailing block, over the leading
  // columns, times their transpose (dense, trailing order). For the augmented factor G = 𝔹K⁻¹𝔹ᵀ.
  Eigen::MatrixXd trailing_gram() const;
  // Whether the augmented factorization captured 𝔹K⁻¹𝔹ᵀ, and that matrix (symmetric, both
  // triangles, trailing order) where it lies: in the factor's trailing block, as long as it lives.
  bool captured_schur() const { return schur_ != nullptr; }
  DenseView schur_block() const;
  std::vector<int> trailing_order() const;  // the `order` of trailing_factor, without the block
  bool augmented() const { return n_aug_ > n_; }

  // Read-only view of the supernodal factor P A Pᵀ = L Lᵀ (A = K, or the augmented matrix):
  // supernode s holds columns super[s] .. super[s+1]-1; its row indices are rows[pi[s] ..
  // pi[s+1]) (its own columns first) and its values a column-major block at values + px[s].
  // perm[k] = the row of A pivoted k-th.
  struct Supernodes {
    std::int64_t count = 0, n = 0;
    const std::int64_t *super = nullptr, *pi = nullptr, *px = nullptr, *rows = nullptr, *perm = nullptr;
    const double* values = nullptr;
  };
  Supernodes supernodes() const;
  int factored_size() const { return n_aug_; }  // n, or n + rows of 𝔹 for the augmented factor

  int size() const { return n_; }
  double factor_nonzeros() const;  // nnz(L)
  double analyze_seconds = 0, factorize_seconds = 0;

 private:
  struct Impl;
  struct ImplDeleter {
    void operator()(Impl* impl) const;
  };
  std::unique_ptr<Impl, ImplDeleter> impl_;  // frees the CHOLMOD factor and workspace, also on throw
  int n_;
  int n_trailing_ = 0;
  int n_aug_ = 0;                  // size of the factored matrix (n_ + rows of 𝔹 for the augmented factor)
  const double* schur_ = nullptr;  // 𝔹K⁻¹𝔹ᵀ captured by the factorization, in the factor's values
  std::int64_t schur_stride_ = 0;  // its leading dimension (the root supernode's rows)
  void record_times();
  Eigen::MatrixXd apply_system(int system, const Eigen::MatrixXd& in) const;
  bool take_schur_block(const class SchurCapture& capture);
  // Whether CHOLMOD's dpotrf_ calls reach the interposer (schur_capture.hpp) in this process: a
  // 3 × 3 augmented matrix factored with a capture armed.
  static bool schur_capture_works();
};

}  // namespace contact3d
