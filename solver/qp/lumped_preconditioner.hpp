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

// The sliding discs' tangent directions (Direction::shift > 0) carry a curvature term that 𝔹K𝔹ᵀ does
// not see; they are preconditioned by the reduced system's diagonal, the others by M⁻¹ (block
// diagonal: symmetric positive definite). On the slab at 2 523, 4 800 and 10 092 multipliers this
// took 16, 24, 16 Newton steps to 13, 17, 14 against M⁻¹ over every direction.
class LumpedPreconditioner {
 public:
  // For the directions `d` of a Newton step on `qp` (which must carry BoxDiscQP::lumped), with the
  // inverse of the reduced system's diagonal.
  LumpedPreconditioner(const BoxDiscQP& qp, const std::vector<Direction>& d, Eigen::VectorXd inverse_diagonal);
  // False where G could not be factored (R𝔹 rank-deficient) or every direction slides: use the diagonal.
  bool usable() const { return usable_; }
  // M⁻¹ r on the directions that do not slide (times the factor set by match_energy), diag⁻¹ r on the others.
  Eigen::VectorXd apply(const Eigen::VectorXd& r) const;
  // Scales M⁻¹ so that sᵀM⁻¹s = sᵀ diag⁻¹ s for r's part s on the directions that do not slide: M⁻¹ is
  // right up to a factor (K's interior is left out), and the two-level preconditioner treats the
  // coarse space exactly, so the fine level must come in the diagonal's units.
  void match_energy(const Eigen::VectorXd& r);

 private:
  Eigen::VectorXd lumped_part(const Eigen::VectorXd& r) const;   // r on lumped_rows_
  Eigen::VectorXd apply_lumped(const Eigen::VectorXd& s) const;  // factor · G⁻¹ (R𝔹K𝔹ᵀRᵀ) G⁻¹ s

  std::vector<Eigen::Index> lumped_rows_;  // the directions that do not slide
  Eigen::VectorXd inverse_diagonal_;
  Eigen::SparseMatrix<double> stiffness_;  // R 𝔹K𝔹ᵀ Rᵀ over lumped_rows_
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> gram_;
  double factor_ = 1;
  bool usable_ = false;
};

}  // namespace contact3d
