// The reduced Newton system of newton_system.hpp, (Dᵀ Q D + diag(shift)) y = b, solved by conjugate
// gradients with one product by Q per iteration, preconditioned by the system's diagonal (its
// Dᵀ diag(Q) D part plus the sliding discs' shifts) or, where the problem gives coarse groups and
// blocked products (BoxDiscQP::coarse_group), by a two-level preconditioner that solves the groups'
// indicators exactly and the rest by the diagonal or, where the problem gives 𝔹𝔹ᵀ and 𝔹K𝔹ᵀ
// (BoxDiscQP::lumped), by FETI's lumped preconditioner (lumped_preconditioner.hpp). For a matrix-free dual
// (linalg/dual_problem.hpp), whose Q has no entries to factor: Newton steps there are inexact, their
// systems solved to a tolerance the caller sets from the current residual (ssn.hpp).
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "qp/box_disc_qp.hpp"
#include "qp/newton_system.hpp"

namespace contact3d {

// Q (D Z) of the two-level preconditioner's coarse space Z for the directions D of the last Newton
// step, kept between steps (BoxDiscQP::coarse_products): a step recomputes only the columns whose
// D Z changed.
struct CoarseProducts {
  Eigen::MatrixXd DZ, QDZ;  // m × groups
};

struct ReducedCgResult {
  int iterations = 0;       // = products by Q (those of the coarse space included)
  int coarse_products = 0;  // of which columns of the two-level preconditioner's blocked product
  int single_products = 0;  // of which through BoxDiscQP::apply_single
  bool converged = false;   // ‖b − A y‖ <= tolerance reached
  double residual = 0;      // the last ‖b − A y‖ (recursive)
};

// From the start `y` (a Newton step's current λ on its directions: the residual is then the gradient
// left there, as small as the iterate is good, not ‖b‖; empty: y = 0); on return y holds the last
// iterate. Stops at ‖b − A y‖ <= `tolerance` (absolute), after `max_iterations` products (the start's
// residual one of them), or when A shows a direction of non-positive curvature (rounding).
// Where the problem has single-precision products (BoxDiscQP::has_single_products) and `tolerance`
// asks to cut the start's residual (computed in double) by at most kSingleCgReduction, the
// iterations' products are single: their rounding (about 4e-7 of the product on the thin slab)
// enters the recursive residual relative to the corrections, which sum to about the start's residual.
// `beat` (may be empty) is called after each iteration with the counts so far (the QP's heartbeat).
inline constexpr double kSingleCgReduction = 1e-4;
using CgHeartbeat = std::function<void(const ReducedCgResult& so_far)>;
ReducedCgResult solve_reduced_cg(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::VectorXd& b,
                                 double tolerance, int max_iterations, Eigen::VectorXd& y,
                                 const CgHeartbeat& beat = {});

// The same preconditioned by the caller's approximate solve M⁻¹ instead (a Newton step's solve
// through a single factor that its refinement could not converge, ssn.cpp): products in double, and
// flexible CG's β (Polak-Ribière), as such an M⁻¹ is symmetric only up to its rounding.
using ReducedPreconditioner = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;
ReducedCgResult solve_reduced_cg(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::VectorXd& b,
                                 double tolerance, int max_iterations, Eigen::VectorXd& y,
                                 const ReducedPreconditioner& preconditioner);

}  // namespace contact3d
