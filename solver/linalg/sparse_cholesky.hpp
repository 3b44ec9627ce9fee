// SparseCholesky: one CHOLMOD supernodal factorization P K Pᵀ = L Lᵀ (METIS/AMD ordering
// chosen by CHOLMOD), reused for every application of K⁻¹. Owns its cholmod_common: no global
// state; not copyable.
#pragma once

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace contact3d {

class SparseCholesky {
 public:
  // Analyze + factorize. Throws std::runtime_error if K is not positive definite (e.g. the
  // clamped part Γu is empty or does not prevent rigid motions).
  explicit SparseCholesky(const Eigen::SparseMatrix<double>& K);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // Several right-hand sides at once (dense, BLAS-3 in CHOLMOD).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B) const;

  int size() const { return n_; }
  double factor_nonzeros() const;  // nnz(L)
  double analyze_seconds = 0, factorize_seconds = 0;

 private:
  struct Impl;
  Impl* impl_;
  int n_;
};

}  // namespace contact3d
