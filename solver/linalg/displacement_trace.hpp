// DisplacementTrace: the displacement w = K⁻¹(f − 𝔹ᵀλ) of (5.5) at a chosen set of dofs S (the
// contact face) for many multiplier vectors λ, without a full solve per λ.
//
// With the augmented factor [K 𝔹ᵀ; 𝔹 σI] = L Lᵀ, L = [L₁₁ 0; L₂₁ L₂₂] (multipliers last),
// K = L₁₁L₁₁ᵀ and 𝔹 = L₂₁L₁₁ᵀ, hence
//     K⁻¹(f − 𝔹ᵀλ) = L₁₁⁻ᵀ (z − L₂₁ᵀλ),   z = L₁₁⁻¹ f (once per scene).
// So each λ costs one back substitution, and only over the supernodes that hold a dof of S or
// are ancestors of one (an entry of L₁₁ᵀx = y at row j depends only on x at j's ancestors).
// The fixed point of section 4 needs u_t on Γc only: this is its per-step solve.
//
// For another 𝔹 than the one factored with K (contact.cell_size = "auto" solving again with smaller
// cells), or a factor of K alone: with W = L₁₁⁻¹P𝔹ᵀ (sparse_forward_solve.hpp),
//     K⁻¹(f − 𝔹ᵀλ) = L₁₁⁻ᵀ (z − Wλ),
// the same back substitution with Wλ in place of L₂₁ᵀλ.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "linalg/sparse_cholesky.hpp"
#include "linalg/sparse_forward_solve.hpp"

namespace contact3d {

class DisplacementTrace {
 public:
  // `factor` must be the augmented factor SparseCholesky(K, 𝔹) and outlive this object;
  // `dofs` are rows of K (S); f the load vector of K.
  DisplacementTrace(const SparseCholesky& factor, const Eigen::VectorXd& f, const std::vector<int>& dofs);
  // Through W = L₁₁⁻¹P𝔹ᵀ (forward_solve_by_supernodes on this factor; it must outlive this object),
  // for any factor of K, augmented or not.
  DisplacementTrace(const SparseCholesky& factor, const Eigen::VectorXd& f, const std::vector<int>& dofs,
                    const ForwardSolvedBlocks& W);

  // w at S (in the order of `dofs`) for the multipliers λ (rows of 𝔹).
  Eigen::VectorXd at(const Eigen::VectorXd& lambda) const;
  // w at every dof: the same back substitution over all supernodes.
  Eigen::VectorXd everywhere(const Eigen::VectorXd& lambda) const;

  // Share of the leading factor's nonzeros one at() call reads (1 = a full back substitution);
  // each call also copies z (O(n), small next to the factor).
  double work_fraction() const { return work_fraction_; }

 private:
  SparseCholesky::Supernodes L_;
  std::int64_t n_ = 0, first_trailing_ = 0;  // K's size; first multiplier column of L
  std::vector<std::int64_t> position_;       // row of the factored matrix -> pivot position
  std::vector<int> dofs_;
  std::vector<std::int64_t> needed_;        // supernodes for at(), descending
  std::vector<std::int64_t> all_;           // every supernode with leading columns, descending
  Eigen::VectorXd z_;                       // L₁₁⁻¹ P f, in pivot order (trailing part unused)
  const ForwardSolvedBlocks* W_ = nullptr;  // L₁₁⁻¹P𝔹ᵀ for another 𝔹, or null: L₂₁ᵀ
  double work_fraction_ = 1;

  DisplacementTrace(const SparseCholesky& factor, const Eigen::VectorXd& f, const std::vector<int>& dofs,
                    const ForwardSolvedBlocks* W);
  Eigen::VectorXd back_substitute(const Eigen::VectorXd& lambda, const std::vector<std::int64_t>& supernodes) const;
};

}  // namespace contact3d
