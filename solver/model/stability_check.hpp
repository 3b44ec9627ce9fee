// The stability condition (5.1) of the multiplier partition, checked on the dual operator: 𝔹 has full
// row rank iff Q = 𝔹K⁻¹𝔹ᵀ is positive definite. The check estimates cond(Q), warns where it makes λ
// unreliable, names the cells of dependent rows (InputError), and hands the QP's Newton steps the
// Cholesky factor of Q it made on the way (qp/bordered_newton.hpp).
#pragma once

#include <memory>

#include "base/progress.hpp"
#include "contact/contact_operator.hpp"
#include "linalg/dual_operator.hpp"
#include "linalg/dual_problem.hpp"
#include "model/contact_solver.hpp"
#include "qp/dual_qp_solver.hpp"

namespace contact3d {

// Stability (5.1) and its warning; cond(Q) on the progress line (res.stability_condition, and
// res.stability_condition_scaled where the Jacobi-scaled QP's condition is what counts). Returns the
// factor of Q for the QP's Newton steps when they are to use it and it fits in memory beside the dual
// solve's copies (`dual_bytes`: what those copies take). ‖Q‖ (Lanczos, estimate_norm) is estimated on the way
// (`q_norm`), through a single-precision copy where the QP's products are single, which the check then
// factors. On the matrix-free route (no Q formed): 𝔹's rank and Lanczos estimates instead, no factor.
std::shared_ptr<DualOperatorFactor> check_dual_stability(const DualProblem& dual, double& q_norm,
                                                         const ContactOperator& op, const QpSettings& qp,
                                                         double dual_bytes, Progress& report, SolveResult& res);

// cond(Q) as the QP sees it (Jacobi-scaled where it scales) beyond what leaves λ reliable: the level of
// check_dual_stability's warning.
// cond(Q) as the QP solves it: the Jacobi-scaled estimate where there is one, else the plain one.
double dual_condition(const SolveResult& res);
bool dual_ill_conditioned(const SolveResult& res);

}  // namespace contact3d
