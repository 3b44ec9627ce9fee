// The default solver of the dual QP (5.5): MPGP and semismooth Newton, each where it is cheap.
// MPGP's iterations cost one product Q·v; its expansion steps of fixed length ᾱ = 1.8/‖Q‖ find
// a large active set slowly (thousands of products on a slab, whose bottom face is half in
// contact, half lifting off). A Newton step costs one dense Cholesky factorization of the free
// size (about m/14 products at m = 4800) and moves whole regions between the active sets at once,
// but settles the last degenerate cells (λ and the gap both ~0) one ring per step. So:
//   1. MPGP in windows of max(25, m/256) iterations while each window cuts ‖gᴾ‖ at least tenfold
//      (m/16 until 2026-11-25, max(50, m/128) until 2026-11-27: long windows let MPGP crawl through
//      expansions that a Newton step makes at once. Once Newton steps went through the factor of Q
//      (bordered_newton.hpp) they were cheap enough for shorter windows: the paper's brick 707 / 748 /
//      807 -> 410 / 425 / 545 products at n = 16 / 24 / 32 in the same time, the slab's dual solve at
//      10 092 multipliers 11.5 -> 7.9 s (constant law) and 31 -> 23 s (ramp law). Shorter still (25
//      at 10 092) starts Newton steps while many cells are still changing set, whose updates of the
//      factor's border then cost more than the MPGP iterations saved: 24-28 s there, ramp law);
//   2. otherwise Newton steps (ssn.hpp) until they converge or stop paying (SlowNewtonSteps: two
//      steps in a row that do not halve ‖F‖, full ones, or after a full one damped ones that cost
//      more than a window; until 2026-11-26 only full steps counted, and on the slab at 10 092
//      multipliers seven damped steps of about 2 s each crept on where MPGP finished in 156
//      iterations);
//   3. then MPGP again from Newton's iterate. After three Newton rounds a further one is taken only
//      while the alternation converges: each round must start at a smaller ‖gᴾ‖ than the round before
//      it (NewtonRoundGate). No limit on a matrix-free Q, whose Newton steps are CG products costing
//      what MPGP's do (capped at three rounds, the slab with 4 800 multipliers took 11 569 products,
//      uncapped 3 739). Until 2026-11-29 a dense Q stopped after three rounds, and MPGP alone crawled
//      where the equality loop of a body held by contact alone asks 1e-12 (the free slab with 4 800
//      multipliers, cond(Q) 1.5e7: ‖gᴾ‖ 1.5e-10 after 20 000 iterations; with the gate five rounds,
//      1 018 products). No limit either with a low-rank term (the augmented Lagrangian's penalty
//      ρĜᵀĜ, BoxDiscQP::low_rank): MPGP's step 1/‖Q + ρĜᵀĜ‖ barely moves λ along Q's own directions,
//      so the Newton steps carry the solve (the ball of ctest
//      ball_on_plane_lateral_load_augmented_lagrangian with one BLAS thread: at ρ = 1e4‖Q‖ the gate
//      stopped the rounds and MPGP ran out of its 1e5 iterations; uncapped, 5 296 iterations).
// On a matrix-free Q the window stays at its floor of 25: a Newton step costs CG products there, not
// a factorization that grows with m, and the longer windows only let MPGP crawl (the slab with
// 37 632 multipliers: windows of 147 iterations, 0.5 s a product, cutting ‖gᴾ‖ by 10-15% each).
// Same stopping test and answer as MPGP: ‖gᴾ(λ)‖ <= rtol ‖h‖ at a feasible λ — or, where rtol lies
// below the rounding of the products and the Newton systems, that floor within ten times rtol
// (RoundingFloor, counted in QpResult::rounding_stops).
#pragma once

#include <cmath>

#include <Eigen/Core>

#include "qp/box_disc_qp.hpp"
#include "qp/mpgp.hpp"

namespace contact3d {

struct HybridSettings {
  double rtol = 1e-6;            // same criterion as MpgpSettings::rtol
  int max_iterations = 100000;   // MPGP iterations + Newton steps
  int max_newton_rounds = 3;     // rounds of Newton steps (step 2) before NewtonRoundGate asks for progress
  int window = 0;                // MPGP iterations per window (0: default_window)
  Progress* progress = nullptr;  // heartbeat (none: silent)
  bool single_products = true;   // MPGP's windows through the single copy of Q where there is one
};

// Whether the hybrid takes another Newton round where an MPGP window was slow: the first
// `free_rounds` always (a matrix-free Q: every one), later ones only while each round starts at a
// smaller ‖gᴾ‖/‖h‖ than the round before it, so that MPGP windows and Newton rounds never alternate
// without converging.
class NewtonRoundGate {
 public:
  explicit NewtonRoundGate(int free_rounds) : free_rounds_(free_rounds) {}
  // A round is due at projected gradient `pg`: true (and counted) when it may be taken.
  bool admit(double pg);

 private:
  int free_rounds_;
  int rounds_ = 0;
  double pg_at_last_round_ = INFINITY;
};

// A tolerance at the rounding floor of the products and the Newton systems' refinements: two Newton
// rounds in a row that end within kRoundGain of each other, and within kRoundingSlack of the target,
// are the floor, and the solve stops there (QpResult::rounding_stops counts it) instead of letting
// MPGP's windows wait for a dip of the noise below the target. The free plate at h = 0.01 (7 500
// multipliers, cond(Q) 3.6e7), the repeat of its last step at 1e-10 with the equality loop's inner
// solves at 1e-12: every Newton round ended at 1.04e-12, and MPGP's windows, their ‖gᴾ‖ between 1.5e-12
// and 5e-11, took 10 288 iterations (50 s) before one dipped under 1e-12.
// MPGP's windows show the floor too, where the Newton systems' own floor lies higher than the
// products' (their rounds then end far above the target and never meet the test above):
// kStalledWindows windows in a row ending within kRoundingSlack of the target that together gain
// less than kRoundGain on the lowest end before them. The strip of pipeline/scenes/strip.toml at
// 4 032 multipliers asked 1e-13 (cond(Q) 1.5e10): its Newton rounds ended at 3e-9, its windows
// between 6.5e-13 and 1e-12 from iteration 1 773 on, 1e-13 never, and the QP ran to its limit of
// 100 000 iterations (150 s) and failed.
class RoundingFloor {
 public:
  static constexpr double kRoundingSlack = 10;  // the floor is accepted within this factor of rtol
  static constexpr double kRoundGain = 0.9;     // a round ending above this share of the best one's gained nothing
  static constexpr int kStalledWindows = 8;
  // A Newton round ended, not converged, at ‖gᴾ‖/‖h‖ = pg: true when it is the floor.
  bool reached(double pg, double rtol);
  // An MPGP window ended, not converged, at ‖gᴾ‖/‖h‖ = pg: true when it is the floor.
  bool reached_by_windows(double pg, double rtol);

 private:
  double best_round_end_ = INFINITY;
  double window_anchor_ = INFINITY;  // the lowest window end before the stalled ones
  int stalled_windows_ = 0;
};

// MPGP iterations per window: max(kMinWindow, m/256) on a dense Q, kMinWindow on a matrix-free one.
inline constexpr int kMinWindow = 25;
int default_window(const BoxDiscQP& qp);

// Warm start from `lambda`; on return it holds the (feasible) solution. iterations counts MPGP
// iterations and Newton steps (newton_steps: the latter), hessian_products the products Q·v.
QpResult solve_hybrid(const BoxDiscQP& qp, Eigen::VectorXd& lambda, const HybridSettings& settings);

}  // namespace contact3d
