// SparseCholesky: one CHOLMOD supernodal factorization P K Pᵀ = L Lᵀ (METIS/AMD ordering
// chosen by CHOLMOD), reused for every application of K⁻¹. Owns its cholmod_common: no global
// state; not copyable.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace contact3d {

class SparseCholesky {
 public:
  // Analyze + factorize. Throws std::runtime_error if K is not positive definite (e.g. the
  // clamped part Γu is empty or does not prevent rigid motions).
  explicit SparseCholesky(const Eigen::SparseMatrix<double>& K);
  // Same factorization with the dofs `trailing` ordered last (METIS on the others, no
  // postorder): the trailing diagonal block L_tt of the factor then satisfies
  // L_tt L_ttᵀ = S, the Schur complement of K onto those dofs, and (K⁻¹)_tt = S⁻¹.
  SparseCholesky(const Eigen::SparseMatrix<double>& K, const std::vector<int>& trailing);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // Several right-hand sides at once (dense, BLAS-3 in CHOLMOD).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B) const;

  // Dense lower-triangular L_tt (only for the `trailing` constructor). `order[k]` is the dof
  // (row of K) of row/column k of L_tt.
  Eigen::MatrixXd trailing_factor(std::vector<int>& order) const;
  int trailing_size() const { return n_trailing_; }

  int size() const { return n_; }
  double factor_nonzeros() const;  // nnz(L)
  double analyze_seconds = 0, factorize_seconds = 0;

 private:
  struct Impl;
  Impl* impl_;
  int n_;
  int n_trailing_ = 0;
  void factor(const Eigen::SparseMatrix<double>& K, const std::vector<int>* trailing);
};

}  // namespace contact3d
