// Semismooth Newton for the dual QP (5.5) with the dense Q (Hüeber, Stadler & Wohlmuth,
// SIAM J. Sci. Comput. 30, 2008, in its projection form): solve
//   F(λ) = λ − P(λ − ρ (Qλ − h)) = 0,
// P the projection onto {λ_n >= 0, ‖λ_t,i‖ <= c_i}, by Newton steps with a generalized
// Jacobian J = I − D (I − ρQ), D ∈ ∂P (0 / identity / sliding tangent on each block). The
// active sets of each step fix part of λ (0 off contact, c ν on a sliding disc); the rest solves a
// symmetric positive definite system of the free size (Q restricted to the free and sliding
// tangent directions, plus a diagonal term per sliding disc), factored by dense Cholesky.
// Damped by a backtracking search on ‖F‖; where that finds no step (a target far outside the feasible
// set, as on slender bodies), a feasible descent step on the QP's objective instead (the unknowns that
// leave early fixed at their bounds, newton_system.hpp's fix_early_exits); if Newton stalls it hands
// the iterate to MPGP (the reference), so the stopping test and the answer are those of MPGP:
// ‖gᴾ(λ)‖ <= rtol ‖h‖ at a feasible λ. With a single-precision copy of Q (BoxDiscQP::Q_single) the
// reduced system is factored in single precision (spotrf, about half the time of dpotrf) and refined
// in double, one product by Q per refinement, until its residual is 1e-10 of the right-hand side;
// otherwise in double. Through the bordered factor of Q (bordered_newton.hpp) where that is cheaper,
// with a Woodbury update for the problem's low-rank term (BoxDiscQP::low_rank, the augmented
// Lagrangian's penalty). On a matrix-free Q (no entries to factor) the steps are inexact: the reduced
// system by CG (reduced_cg.hpp) from the current iterate, to a forcing term of
// min(0.01, √(‖gᴾ‖/‖h‖)) · ‖gᴾ‖.
#pragma once

#include <limits>

#include <Eigen/Core>

#include "qp/box_disc_qp.hpp"
#include "qp/mpgp.hpp"

namespace contact3d {

struct SsnSettings {
  double rtol = 1e-6;                 // same criterion as MpgpSettings::rtol
  int max_newton = 40;                // Newton steps before falling back to MPGP
  int max_iterations = 100000;        // for the MPGP fallback
  Progress* progress = nullptr;       // heartbeat (none: silent)
  const QpResult* earlier = nullptr;  // the same QP's work before this call, counted in the heartbeat
  // For the hybrid solver (qp/hybrid_qp.hpp): return (status IterationLimit) once the steps stop
  // paying (SlowNewtonSteps), and return instead of running MPGP when Newton fails.
  bool stop_when_linear = false;
  bool fallback_to_mpgp = true;
  // With stop_when_linear: a damped step after a full one that does not halve ‖F‖ counts as slow too
  // when its reduced factorization costs more than this many products by Q (SlowNewtonSteps). Such
  // steps crept (3-30% of ‖F‖ each on a slab with 10 092 multipliers, 1 500 products' worth of flops
  // apiece) where MPGP finishes for less.
  double damped_step_budget = std::numeric_limits<double>::infinity();
};

// When Newton steps stop paying (the hybrid's round ends, SsnSettings::stop_when_linear): two steps
// in a row that do not halve ‖F‖. Full steps count: the active sets are settling a few cells at a
// time (degenerate cells, λ and the gap both ~0), where MPGP finishes far more cheaply. Damped steps
// count after a full one (Newton has left its local regime) when they cost more than
// `damped_step_budget` products (newton_step_cost); damped steps before any full step are the
// globalization Newton needs far from the solution, and go on.
class SlowNewtonSteps {
 public:
  explicit SlowNewtonSteps(double damped_step_budget) : damped_step_budget_(damped_step_budget) {}
  // One accepted step of length `step_length` (1: full) that took ‖F‖ from F_before to F_after and
  // cost `cost` products; true when the steps stop paying.
  bool record(double step_length, double F_before, double F_after, double cost);

 private:
  double damped_step_budget_;
  int in_a_row_ = 0;
  bool took_full_step_ = false;
};

// The flops of a Newton step's factorization (k³/3 for k free directions) in products by the
// m x m Q (2m² each): an upper estimate of its time (dpotrf runs nearer peak than a product).
double newton_step_cost(int free_directions, int m);

// Warm start from `lambda`; on return it holds the (feasible) solution. iterations counts
// Newton steps (+ MPGP iterations of a fallback); hessian_products counts products Q·v.
QpResult solve_ssn(const BoxDiscQP& qp, Eigen::VectorXd& lambda, const SsnSettings& settings);

}  // namespace contact3d
