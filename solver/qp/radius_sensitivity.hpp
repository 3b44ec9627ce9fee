// RadiusSensitivity: how the solution λ(c) of the dual QP (5.5) moves with the disc radii c (5.3),
// at a solution λ, its active sets held fixed. Differentiating F(λ, c) = λ − P_c(λ − ρ(Qλ − h)) = 0:
// J dλ = ∂P/∂c dc, and ∂P/∂c is ν_i (the sliding direction) on a sliding disc, 0 elsewhere. In the
// reduced form of newton_system.hpp:
//   dλ = dλ_fixed + D dy,   dλ_fixed = dc_i ν_i on each sliding disc,
//   (Dᵀ Q D + diag(shift)) dy = −Dᵀ Q dλ_fixed.
// The reduced system is solved once per solution's active sets: through the factor of the whole Q
// that the QP's Newton steps use (qp.bordered, bordered_newton.hpp) where that is cheaper, else by a
// dense Cholesky factorization of the free size (in single precision where the QP's products are:
// half the memory, as the QP's own Newton steps). Each apply() is then two products by Q (the
// right-hand side and one step of refinement in double) and the triangular solves. On a matrix-free
// Q (no entries to factor) each apply() solves it by CG instead (reduced_cg.hpp, to kCgRelativeResidual),
// started from the Galerkin projection onto the earlier applies' solutions, kept A-orthonormal: the
// fixed point's successive predictions ask for nearby right-hand sides, so CG has little left to do.
// The fixed point's Newton and predicted steps use it (friction/tresca_step.hpp): the derivative of
// G(φ) = slip(λ(c(φ))).
//
// With equality constraints Gλ = e (a body held by contact alone, dual_qp_solver.hpp) the linear
// term is h − Gᵀμ and μ moves too, so that G dλ = 0: with Z = A⁻¹DᵀGᵀ (k reduced solves, once),
// dy = dy₀ − Z dμ and (G D Z) dμ = G(dλ_fixed + D dy₀); equality_change() gives that dμ.
//
// The problem may be a Jacobi-scaled one (jacobi_scaling.hpp: λ = S μ, radii c / s_t): `scale` = S
// then maps its answers back, so that apply() takes and returns the original variables.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/QR>

#include "linalg/dense_cholesky.hpp"
#include "qp/box_disc_qp.hpp"
#include "qp/newton_system.hpp"

namespace contact3d {

class RadiusSensitivity {
 public:
  static constexpr int kProductsPerApply = 2;  // products by Q of one apply(), where it factors (see products())
  // Matrix-free: CG's stopping residual relative to the right-hand side's norm, its product limit,
  // and how many earlier solutions the start's Galerkin projection keeps. A prediction is a proposal
  // that the next solve checks, so 1e-3 is enough: against 1e-4 (1e-6), n_mult of the matrix-free
  // roller 2 075 against 2 205 (2 662), split ring 2 640 against 3 203 (3 616), same steps.
  static constexpr double kCgRelativeResidual = 1e-3;
  static constexpr int kMaxCgProducts = 2000, kRecycledSolutions = 30;
  // The equality Jacobian's k solves at once (solve_reduced_columns): refined in double until a
  // correction is at most this fraction of the answer, in at most this many steps.
  static constexpr double kRefinedCorrection = 1e-2;
  static constexpr int kMaxRefinements = 4;

  // `qp` is the problem λ (or μ = S⁻¹λ) solves, copied (its Q, and its bordered solver if any, must
  // outlive this object); `solution` a (converged) solution of it; `scale` = S when `qp` is the
  // Jacobi-scaled problem of the original one (empty: `qp` is the original).
  // `equality`: G of the constraints Gλ = e in the original variables (empty: none).
  RadiusSensitivity(const BoxDiscQP& qp, const Eigen::VectorXd& solution, bool single_precision,
                    const Eigen::VectorXd& scale = {}, const Eigen::MatrixXd& equality = {});
  // False when the reduced matrix is not numerically positive definite (then apply() returns 0).
  bool ok() const { return ok_; }
  // Whether the reduced system goes through the factor of the whole Q (qp.bordered).
  bool through_factor_of_Q() const { return bordered_preparation_ >= 0; }
  // Products by Q so far: kProductsPerApply per apply() where the reduced system is factored (the
  // paper's count); matrix-free, those the construction and each apply()'s CG took.
  int products() const { return products_; }
  // dλ for a change dc of the radii (size r), in the original variables. Not const: should the
  // bordered solver have been prepared for another system since, it prepares ours again (or, failing
  // that, factors the reduced matrix).
  Eigen::VectorXd apply(const Eigen::VectorXd& dc);
  // With equality constraints: G dλ/dμ = −G D Z, the response of Gλ to the multiplier μ with the
  // active sets held (the Jacobian of the equality loop's F(μ) = Gλ(μ) − e is its negative); none
  // where the reduced system cannot be solved.
  std::optional<Eigen::MatrixXd> equality_response();
  // dμ of the last apply() (size k; empty without equality constraints).
  const Eigen::VectorXd& equality_change() const { return dmu_; }
  // The active sets it holds, and A⁻¹B for the columns of B (A = Dᵀ Q D + diag(shift) of those sets)
  // refined in double until a correction is at most `correction` of the answer, at most `refinements`
  // steps; none where A cannot be solved. The joint Newton steps of equality_newton.hpp use them.
  const ReducedStep& active_sets() const { return step_; }
  std::optional<Eigen::MatrixXd> solve_columns(const Eigen::MatrixXd& B, double correction, int refinements);

 private:
  bool factor_reduced_matrix();
  bool bordered_ready();
  // False when no route is left (the lazily made factor failed).
  bool solve_reduced(const Eigen::VectorXd& b, Eigen::VectorXd& y);
  // The same for B's columns at once, refined to `refined_to` in at most `refinements` steps.
  bool solve_reduced_columns(const Eigen::MatrixXd& B, Eigen::MatrixXd& Y, double refined_to = kRefinedCorrection,
                             int refinements = kMaxRefinements);
  bool solve_reduced_by_cg(const Eigen::VectorXd& b, Eigen::VectorXd& y);
  void remember(Eigen::VectorXd p, Eigen::VectorXd Ap);  // adds a solution to the recycled basis
  bool prepare_equality();                               // Z and G D Z, on the first apply()

  BoxDiscQP qp_;
  Eigen::VectorXd scale_;  // S (empty: none)
  bool single_precision_;
  ReducedStep step_;
  Eigen::VectorXd nu_;  // the sliding direction ν_i of each sliding disc (at t1, t2), 0 elsewhere
  // qp_.bordered->preparations() after preparing ours (−1: not that route); the factors below are
  // made lazily should the bordered route be lost.
  long bordered_preparation_ = -1;
  std::optional<DenseCholesky> factor_;
  std::optional<SingleCholesky> single_factor_;
  ReducedOperator refinement_;  // the refinement's products (kept in double beside a single factor)
  // Matrix-free: earlier solutions p_j of the reduced system, A-orthonormal, with A p_j.
  std::vector<Eigen::VectorXd> recycled_, recycled_products_;
  int products_ = 0;
  bool ok_ = false;
  // Equality constraints: G in the problem's variables (G S where scaled), Z = A⁻¹DᵀGᵀ (reduced size
  // × k, empty until prepared) and the decomposition of G D Z; dμ of the last apply().
  Eigen::MatrixXd G_, Z_, GDZ_matrix_;
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> GDZ_;
  Eigen::VectorXd dmu_;
};

}  // namespace contact3d
