// The data of the dual problem (5.5)-(5.6): Q = 𝔹 K⁻¹ 𝔹ᵀ (dense, contact-sized) and
// h = 𝔹 K⁻¹ f, computed once per scene from one factorization of K. Forming Q explicitly
// turns every later "multiplication by K⁻¹" of the dual solver into a dense product of
// contact size.
#pragma once

#include <functional>

#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "linalg/dense_view.hpp"
#include "linalg/sparse_cholesky.hpp"
#include "linalg/symmetric_product.hpp"

namespace contact3d {

struct DualOperator {
  Eigen::MatrixXd Q;  // empty where Q stays in the factor
  // The augmented route: Q where the factorization left it, in the factor's trailing block (valid
  // while the factor lives; SparseCholesky::schur_block).
  DenseViewPtr Q_in_factor;
  Eigen::VectorXd h;
  // Q wherever it is held.
  DenseView Q_view() const { return Q_in_factor ? *Q_in_factor : DenseView(Q); }
  Eigen::VectorXd u_free;  // K⁻¹ f, the unconstrained solution
  int solves = 0;          // right-hand sides solved with the factor to build this
};

// Solves K X = 𝔹ᵀ in blocks of at most `block_columns` right-hand sides, fewer on big meshes so a
// block stays near 64 MiB.
DualOperator make_dual_operator(const SparseCholesky& K, const Eigen::SparseMatrix<double>& B, const Eigen::VectorXd& f,
                                int block_columns = 256);

// The same from a factor built with the dofs touched by 𝔹 ordered last (see
// contact_dofs / SparseCholesky(K, trailing)): Q = (L_tt⁻¹𝔹_tᵀ)ᵀ(L_tt⁻¹𝔹_tᵀ) by one dense
// triangular solve and one symmetric rank-k product (BLAS dtrsm + dsyrk); one solve for h.
DualOperator make_dual_operator_schur(const SparseCholesky& K, const Eigen::SparseMatrix<double>& B,
                                      const Eigen::VectorXd& f);

// The same from the augmented factor SparseCholesky(K, 𝔹): Q = the Schur block that factorization
// captured, left in the factor (Q_in_factor) when the factor keeps 𝔹's rows in their order (the
// usual case), else permuted into Q; L_21 L_21ᵀ where nothing was captured. One solve for h (none
// when the caller passes u_free = K⁻¹f, e.g. from DisplacementTrace::everywhere(0)).
DualOperator make_dual_operator_augmented(SparseCholesky& K_aug, const Eigen::SparseMatrix<double>& B,
                                          const Eigen::VectorXd& f, const Eigen::VectorXd* u_free = nullptr);

// Q's diagonal ‖Wᵢ‖² from 𝔹's rows forward-solved, W = L⁻¹P𝔹ᵀ (the factor of K alone, not augmented),
// in blocks of `block_columns` neighbouring rows over their reach (sparse_forward_solve.hpp), each block
// dropped once its columns' norms are taken: no m × m array and no W kept (16 MiB of workspace).
Eigen::VectorXd forward_solved_diagonal(const SparseCholesky& K, const Eigen::SparseMatrix<double>& B,
                                        int block_columns = 256);

// Columns per dense block of right-hand sides of `rows` rows: at most `requested`, fewer on big
// meshes so that a block stays near `block_bytes` (at least 8 columns).
int block_columns_for(Eigen::Index rows, int requested, long long block_bytes = 64LL << 20);

// The dofs (columns) on which 𝔹 has a nonzero, ascending.
std::vector<int> contact_dofs(const Eigen::SparseMatrix<double>& B);

// Largest eigenvalue of a symmetric positive semidefinite matrix by Lanczos steps (fully
// reorthogonalised, from a fixed pseudo-random start), stopped once the top Ritz pair's residual is
// 1e-3 of it, after 10 to `iterations` products. A Ritz value is from below; callers add a 5% margin,
// and MPGP's step ᾱ = 1.8/‖Q‖ still decreases S if the estimate is low by up to 10%. (A power
// iteration of 50 products did this before, within ~1% on dual operators; Lanczos meets 1e-3 there
// after 4 to 6 products.)
double estimate_norm(const DenseView& Q, int iterations = 50);
// The same through a single-precision copy (Q = scale · Q_single, its lower triangle read; symmetric_product.hpp):
// half the bytes per product, and the estimate differs from the one in double by single's rounding.
double estimate_norm(const SingleSymmetric& Q_single, double scale, int iterations = 50);
// The same for an operator given by its product v ↦ A v (of vectors of `size`).
double estimate_norm(Eigen::Index size, const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& product,
                     int iterations = 50);

// The extreme eigenvalues of a symmetric positive semidefinite operator given by its product, from
// `steps` Lanczos steps (fully reorthogonalised, from a fixed pseudo-random start): Ritz values lie
// inside the spectrum, so `largest` is from below (as a power iteration's, and closer for the same
// products) and `smallest` from above — their ratio estimates the condition number from below.
struct SpectrumEstimate {
  double largest = 0, smallest = 0;
  int products = 0;
};
SpectrumEstimate lanczos_extremes(Eigen::Index size,
                                  const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& product,
                                  int steps = 40);

}  // namespace contact3d
