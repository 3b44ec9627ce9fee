// DisplacementTrace: the displacement w = K⁻¹(f − 𝔹ᵀλ) of (5.5) at a chosen set of dofs S (the
// contact face) for many multiplier vectors λ, without a full solve per λ.
//
// With the augmented factor [K 𝔹ᵀ; 𝔹 σI] = L Lᵀ, L = [L₁₁ 0; L₂₁ L₂₂] (multipliers last),
// K = L₁₁L₁₁ᵀ and 𝔹 = L₂₁L₁₁ᵀ, hence
//     K⁻¹(f − 𝔹ᵀλ) = L₁₁⁻ᵀ (z − L₂₁ᵀλ),   z = L₁₁⁻¹ f (once per scene).
// So each λ costs one back substitution, and only over the supernodes that hold a dof of S or
// are ancestors of one (an entry of L₁₁ᵀx = y at row j depends only on x at j's ancestors).
// The fixed point of section 4 needs u_t on Γc only: this is its per-step solve.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "linalg/sparse_cholesky.hpp"

namespace contact3d {

class DisplacementTrace {
 public:
  // `factor` must be the augmented factor SparseCholesky(K, 𝔹) and outlive this object;
  // `dofs` are rows of K (S); f the load vector of K.
  DisplacementTrace(const SparseCholesky& factor, const Eigen::VectorXd& f, const std::vector<int>& dofs);

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
  std::vector<std::int64_t> needed_;  // supernodes for at(), descending
  std::vector<std::int64_t> all_;     // every supernode with leading columns, descending
  Eigen::VectorXd z_;                 // L₁₁⁻¹ P f, in pivot order (trailing part unused)
  double work_fraction_ = 1;

  Eigen::VectorXd back_substitute(const Eigen::VectorXd& lambda, const std::vector<std::int64_t>& supernodes) const;
};

}  // namespace contact3d
