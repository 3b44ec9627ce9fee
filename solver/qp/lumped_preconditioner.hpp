// The lumped preconditioner of FETI, for the reduced Newton systems of a dual operator
// Q = 𝔹K⁻¹𝔹ᵀ (5.6) that has no entries (the matrix-free dual): where 𝔹 were square and K's
// interior absent, Q⁻¹ would be 𝔹⁻ᵀK𝔹⁻¹; lumped, K is kept on Γc's dofs only and 𝔹⁻¹ becomes
// the pseudo-inverse of the rows that a Newton step moves. For its directions R = Dᵀ S (the
// directions D of newton_system.hpp, S the Jacobi scaling, i.e. BoxDiscQP::entry_factor), the
// reduced operator is A = R 𝔹K⁻¹𝔹ᵀ Rᵀ and
//   M⁻¹ = G⁻¹ (R 𝔹K𝔹ᵀ Rᵀ) G⁻¹,   G = R 𝔹𝔹ᵀ Rᵀ,
// symmetric positive definite where R𝔹 has full row rank (stability (5.1)). It costs two sparse
// solves with G (cells sharing nodes couple) and one sparse product per application, against a
// solve through the factor of K for a product by Q. On the thin slab at 4 800 multipliers it cut the
// Newton steps' CG products threefold under the two-level preconditioner (reduced_cg.hpp), of
// which it is then the fine level.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "qp/box_disc_qp.hpp"
#include "qp/newton_system.hpp"

namespace contact3d {

// 𝔹𝔹ᵀ and 𝔹K𝔹ᵀ in the original (unscaled) multipliers: m × m, sparse.
struct LumpedOperators {
  Eigen::SparseMatrix<double> gram, stiffness;
};
LumpedOperators make_lumped_operators(const Eigen::SparseMatrix<double>& B, const Eigen::SparseMatrix<double>& K);
double lumped_operator_bytes(const LumpedOperators& lumped);

class LumpedPreconditioner {
 public:
  // For the directions `d` of a Newton step on `qp` (which must carry BoxDiscQP::lumped).
  LumpedPreconditioner(const BoxDiscQP& qp, const std::vector<Direction>& d);
  // False where G could not be factored (R𝔹 rank-deficient): use another preconditioner.
  bool usable() const { return usable_; }
  // M⁻¹ r, times the factor set by match_energy.
  Eigen::VectorXd apply(const Eigen::VectorXd& r) const;
  // Scales M⁻¹ so that rᵀM⁻¹r = rᵀ diag(A)⁻¹ r: M⁻¹ is right up to a factor (K's interior is left
  // out), and the two-level preconditioner treats the coarse space exactly, so the fine level must
  // come in the diagonal's units.
  void match_energy(const Eigen::VectorXd& r, const Eigen::VectorXd& inverse_diagonal);

 private:
  Eigen::SparseMatrix<double> stiffness_;  // R 𝔹K𝔹ᵀ Rᵀ
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> gram_;
  double factor_ = 1;
  bool usable_ = false;
};

}  // namespace contact3d
