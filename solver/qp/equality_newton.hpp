// Semismooth Newton steps on the pair (λ, μ) of the dual QP (5.5) with equality constraints Gλ = e
// (a body held by contact alone: dual_qp_solver.hpp, model/held_by_contact.hpp). The equality loop
// of DualQpSolver steps on μ alone and solves a whole QP for λ(μ) after each step; these steps move
// both at once. On the residual
//   F(λ, μ) = [λ − P(λ − ρ(Qλ − h + Gᵀμ));  P_C(Gλ − e)],   P_C = C Cᵀ (the balance conditions kept),
// one step fixes λ's active sets at z = λ − ρ g (newton_system.hpp: λ = λ_fixed + D y) and borders
// their reduced system A y = Dᵀ(h − Gᵀμ − Qλ_fixed) with the k equality rows:
//   y = y₀ − Z δ,   Z = A⁻¹DᵀGᵀ,   (Cᵀ G D Z C) δ' = Cᵀ(G(λ_fixed + D y₀) − e),   δ = C δ',
// k + 1 reduced solves with one factor (through the factor of Q where the QP's Newton steps go,
// radius_sensitivity.hpp), instead of a QP solve per step. The steps are taken whole, as a
// primal-dual active set method takes them; they are given up on a cycle of the active sets, on steps
// that more than double ‖F₁‖² + (‖F₂‖ / ‖G‖)², or where that merit makes no progress (equality_newton.cpp).
// Damped (EqualityNewtonSettings::damped), a step that would raise the merit steeply is halved until
// it falls: slower where whole steps converge, but it converges where their first target lies far
// from the answer.
// Dense Q only (the reduced systems need its entries).
#pragma once

#include <Eigen/Core>

#include "qp/box_disc_qp.hpp"
#include "qp/mpgp.hpp"

namespace contact3d {

struct EqualityNewtonSettings {
  double rtol = 1e-8;  // λ: ‖gᴾ‖ <= rtol ‖h − Gᵀμ‖ at a feasible λ (the inner solves' criterion)
  double balance_target = 0;      // μ: ‖P_C(Gλ − e)‖ <= balance_target
  int max_steps = 100;            // Newton steps before giving up
  bool single_precision = false;  // the reduced systems factored in single precision (refined in double)
  // Steps that would raise the merit more than kSteepRise² fold are halved (down to 1/64) until it
  // falls: the second try where the whole steps were given up (DualQpSolver's equality loop).
  bool damped = false;
};

struct EqualityNewtonResult {
  bool converged = false;
  Eigen::VectorXd lambda;    // feasible (projected), in the problem's variables
  Eigen::VectorXd mu_shift;  // δμ: the answer's multiplier is μ + δμ, the problem's linear term being h − Gᵀμ
  Eigen::MatrixXd response;  // G D Z at the last step (the equality loop's Jacobian is its negative)
  // Not converged, but its least-merit iterate (then in lambda and mu_shift) has under a quarter of the
  // start's merit: a start for the caller's own steps on μ, which would otherwise begin again from theirs.
  bool improved = false;
  QpResult work;  // Newton steps and products
};

// `problem`: the QP for the current μ (its linear term h − Gᵀμ), Jacobi-scaled or not; `G` (k × m) in
// its variables; `conditions` C (k × r, orthonormal columns) the balance conditions to meet; `start` a
// feasible λ. Converged when both tests of EqualityNewtonSettings hold; otherwise the caller keeps its
// own iterate, or takes the least-merit one where it is `improved`.
EqualityNewtonResult solve_equality_newton(const BoxDiscQP& problem, const Eigen::MatrixXd& G, const Eigen::VectorXd& e,
                                           const Eigen::MatrixXd& conditions, const Eigen::VectorXd& start,
                                           const EqualityNewtonSettings& settings);

}  // namespace contact3d
