// Cholesky factorization of a dense symmetric positive definite matrix (LAPACK dpotrf: blocked,
// on the BLAS threads; Eigen's LLT below a size where waking the threads costs more than the
// factorization). Used for the dense dual operator Q (the stability check (5.1)) and the reduced
// Newton systems of the semismooth Newton QP solver.
#pragma once

#include <cstddef>
#include <optional>

#include <Eigen/Core>

#include "linalg/dense_view.hpp"
#include "linalg/symmetric_product.hpp"

namespace contact3d {

class DenseCholesky {
 public:
  // Factors the lower triangle of `A` in place (A is taken by value: pass std::move to reuse its
  // storage). ok() is false when A is not numerically positive definite.
  explicit DenseCholesky(Eigen::MatrixXd A);
  bool ok() const { return ok_; }
  // x = A⁻¹ b, and X = A⁻¹ B for several right-hand sides at once (one pass over the factor).
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  Eigen::MatrixXd solve_columns(const Eigen::MatrixXd& B) const;
  // The squared diagonal of the factor (the pivots of LDLᵀ): tiny ones flag near-dependence.
  Eigen::VectorXd pivots() const { return L_.diagonal().cwiseAbs2(); }
  // The factor L of A = L Lᵀ (its lower triangle; the strict upper one holds no meaning).
  const Eigen::MatrixXd& lower() const { return L_; }

 private:
  Eigen::MatrixXd L_;
  bool ok_ = false;
};

// The same in single precision (LAPACK spotrf: half the bytes and about half the time of dpotrf at
// 4800 rows), for solves whose answer is refined in double by the caller (iterative refinement).
class SingleCholesky {
 public:
  // Factors the lower triangle of `A` (m × m, or m × (m + 1): see spare_upper); ok() is false when
  // it is not positive definite in single.
  explicit SingleCholesky(Eigen::MatrixXf A);
  bool ok() const { return ok_; }
  // x = A⁻¹ b, and X = A⁻¹ B for several right-hand sides at once, computed in single precision.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  Eigen::MatrixXd solve_columns(const Eigen::MatrixXd& B) const;
  Eigen::VectorXd pivots() const { return L_.diagonal().cast<double>().cwiseAbs2(); }
  const Eigen::MatrixXf& lower() const { return L_; }
  // With an array of m × (m + 1), the factor fills the lower triangle of its first m columns and
  // leaves the upper triangle of the last m free (column j + 1's rows 0..j): a symmetric m × m
  // matrix may be kept there as an upper triangle with columns m apart (upper_triangle_in_single),
  // instead of a second array. Null where the array has no spare column.
  float* spare_upper() { return L_.cols() == L_.rows() + 1 ? L_.data() + L_.rows() : nullptr; }

 private:
  Eigen::MatrixXf L_;
  bool ok_ = false;
};

// A Cholesky factor of the dense dual operator kept past the stability check (5.1), for the Newton
// steps of the QP (qp/bordered_newton.hpp): Q = scale · L Lᵀ, L in double or in single precision
// (exactly one of them is set).
struct DualOperatorFactor {
  std::optional<DenseCholesky> in_double;
  std::optional<SingleCholesky> in_single;
  double scale = 1;
  std::size_t bytes() const {
    const auto m = static_cast<std::size_t>(in_double ? in_double->lower().rows() : in_single->lower().rows());
    return in_double ? m * m * sizeof(double) : static_cast<std::size_t>(in_single->lower().size()) * sizeof(float);
  }
};

// An estimate of the smallest eigenvalue of the symmetric positive definite `A`, given its factor:
// subspace iteration on A⁻¹ with a block of 8 vectors (each iteration one pass over the factor, as
// costly as a single-vector solve, which is memory-bound), then the Rayleigh–Ritz value on the block.
// From above: the estimate is never below the true λmin. With the factor of A in single precision
// the block converges to the same eigenvectors to single's accuracy and the Rayleigh–Ritz values,
// taken with A in double, are accurate to its square (a unit test checks both against an exact
// spectrum): half the factorization's time and memory for the same estimate.
// With `scale` (a positive diagonal S, e.g. D^{-1/2} for the Jacobi scaling): the smallest eigenvalue
// of S A S, through the same factor of A ((S A S)⁻¹ = S⁻¹ A⁻¹ S⁻¹).
double smallest_eigenvalue(const DenseCholesky& factor, const DenseView& A, const Eigen::VectorXd& scale = {});
double smallest_eigenvalue(const SingleCholesky& factor, const DenseView& A, const Eigen::VectorXd& scale = {});

}  // namespace contact3d
