// RadiusSensitivity: how the solution λ(c) of the dual QP (5.5) moves with the disc radii c (5.3),
// at a solution λ, its active sets held fixed. Differentiating F(λ, c) = λ − P_c(λ − ρ(Qλ − h)) = 0:
// J dλ = ∂P/∂c dc, and ∂P/∂c is ν_i (the sliding direction) on a sliding disc, 0 elsewhere. In the
// reduced form of newton_system.hpp:
//   dλ = dλ_fixed + D dy,   dλ_fixed = dc_i ν_i on each sliding disc,
//   (Dᵀ Q D + diag(shift)) dy = −Dᵀ Q dλ_fixed.
// The matrix is factored once per solution (dense Cholesky of the free size, in single precision
// where the QP's products are: half the memory, as the QP's own Newton steps); each apply() is then
// two products by Q (the right-hand side and one step of refinement in double) and four triangular
// solves. The fixed point's Newton steps use it (friction/tresca_step.hpp): the derivative of
// G(φ) = slip(λ(c(φ))).
#pragma once

#include <optional>

#include <Eigen/Core>

#include "linalg/dense_cholesky.hpp"
#include "qp/box_disc_qp.hpp"
#include "qp/newton_system.hpp"

namespace contact3d {

class RadiusSensitivity {
 public:
  static constexpr int kProductsPerApply = 2;  // products by Q of one apply()

  // `qp` (with the radii λ solves) must outlive this object; λ a (converged) solution.
  RadiusSensitivity(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, bool single_precision);
  // False when the reduced matrix is not numerically positive definite (then apply() returns 0).
  bool ok() const { return ok_; }
  // dλ for a change dc of the radii (size r).
  Eigen::VectorXd apply(const Eigen::VectorXd& dc) const;

 private:
  Eigen::VectorXd solve_reduced(const Eigen::VectorXd& b) const;

  const BoxDiscQP& qp_;
  ReducedStep step_;
  Eigen::VectorXd nu_;  // the sliding direction ν_i of each sliding disc (at t1, t2), 0 elsewhere
  std::optional<DenseCholesky> factor_;
  std::optional<SingleCholesky> single_factor_;
  bool ok_ = false;
};

}  // namespace contact3d
