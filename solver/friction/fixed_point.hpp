// The method of successive approximations (5.7) for the solution-dependent coefficient:
// φ⁰ = 0; step k solves the Tresca problem with radii c(φᵏ⁻¹) and returns the nodal slip
// G(φᵏ⁻¹) = ‖w_t‖ at the contact nodes. err(k) = ‖G(φᵏ⁻¹) − φᵏ⁻¹‖ / ‖G(φᵏ⁻¹)‖, which for the
// plain iteration φᵏ = G(φᵏ⁻¹) is the paper's ‖φᵏ − φᵏ⁻¹‖ / ‖φᵏ‖. The Anderson variant mixes the
// last few iterates (safeguarded: non-negative slip, restart when err grows).
//
// The inner (QP) tolerance never sets the floor. G is only evaluated to the QP tolerance, so step
// k is solved to min(qp_rtol, qp_rtol_per_err · err(k−1)): the QP's error in G falls with err
// instead of staying at the level qp_rtol leaves (on a thin slab 1e-3 of the slip at 1e-6, which
// stalled err above tol and fed the relaxation wrong secants). On top of that, a
// step whose err does not fall (err(k) > 0.7 err(k−1)) while its warm-started QP hardly moved (at
// most max(5, 1/20 of the first step's) iterations) is taken as inner noise, and the QP tolerance
// is tightened 100× (down to `qp_rtol_floor`) before anything else is concluded. Stagnation — no
// new minimum of err for `stagnation_window` steps — is only declared when inner noise is ruled
// out (the QP is at the floor, or busy with every step) and the iterates are not travelling one way
// (a slip front spreading over a large face raises err for many steps while the last residuals
// G(φ) − φ stay aligned), i.e. when the map itself does not contract. In the tail (err < tail_err)
// the accelerated variant takes Newton steps on φ − G(φ) = 0 where G gives its derivative
// (SlipEvaluation::derivative: the Tresca solve's sensitivity to the radii), by GMRES. An accelerated variant
// (Aitken, Anderson) that would stagnate falls back to the plain steps first (a relaxed step breaks
// a slow front's alignment; plain steps ride it out) and stagnates only if they do too. The observed
// contraction factor q (the largest ratio of successive steps ‖φᵏ⁺¹ − φᵏ‖ / ‖φᵏ − φᵏ⁻¹‖ over the last three) gives the
// a posteriori estimate ‖φ* − φᵏ‖ <= q / (1 − q) ‖φᵏ − φᵏ⁻¹‖ of the distance to the fixed point when q < 1. It is
// a bound where q bounds the map's Lipschitz constant near φ*; q is observed, not proven, so where the
// contraction slows in the tail the estimate can fall short (a slip-weakening law under Coulomb on the
// split ring: the slip's distance 1.221e-4 against the estimate 1.217e-4).
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/named_enum.hpp"

namespace contact3d {

enum class FixedPointStatus { Converged, IterationLimit, Stagnation, InnerSolverFailed };

// Plain: φᵏ = G(φᵏ⁻¹), the paper's (5.7). Anderson: mixing of the last `anderson_depth` iterates
// from the start. Aitken: Aitken's dynamic relaxation φᵏ = φᵏ⁻¹ + ωₖ(G(φᵏ⁻¹) − φᵏ⁻¹), ωₖ the
// secant step along the residual, from the start. Accelerated (the default): the paper's plain
// iteration while each step is under half the one before (so scenes it handles keep its steps
// exactly: the brick's 6), then, from the first step that is not, predicted steps (the fixed point
// of G's prediction, where G gives one and its successive approximations converge), else Aitken's
// relaxation, and in the tail (err < tail_err) Newton steps on φ − G(φ) = 0 where G gives its
// derivative, Anderson mixing where it does not — each safeguarded: after two failures of a kind
// the run goes on without it.
enum class FixedPointVariant { Plain, Anderson, Accelerated, Aitken };
inline constexpr NameTable<FixedPointVariant, 4> kFixedPointVariantNames{
    {{FixedPointVariant::Plain, "plain"},
     {FixedPointVariant::Anderson, "anderson"},
     {FixedPointVariant::Accelerated, "accelerated"},
     {FixedPointVariant::Aitken, "aitken"}}};
std::string to_string(FixedPointStatus s);

struct FixedPointSettings {
  double tol = 1e-4;
  int max_iterations = 100;
  FixedPointVariant variant = FixedPointVariant::Accelerated;
  int anderson_depth = 5;
  // Accelerated: the tail begins once err < tail_err (and the iterates no longer travel one way);
  // there Newton steps on φ − G(φ) = 0 (where G gives its derivative and `newton` is on), else
  // Anderson mixing (depth anderson_depth), replace the relaxation. 0: no tail, relaxation to the end.
  double tail_err = 0.1;
  bool newton = true;
  // Accelerated, once it relaxes: where G gives a prediction (SlipEvaluation::predict), the next input
  // is the fixed point of that prediction — G's answer moved along its sensitivity to the radii, with
  // the law exact — found by successive approximations on the prediction alone (no QP solve), when
  // they converge; safeguarded like the tail's steps. off: the relaxation and tail as before.
  bool predicted_steps = true;
  int stagnation_window = 8;  // stop when err has not reached a new minimum for this many steps
  // Inexact early steps: QP tolerance max(qp_rtol, min(1e-3, 1e-2·err(k−1))); a step that meets
  // `tol` with a looser QP tolerance is repeated exactly before declaring convergence.
  bool inexact = false;
  // Noise-aware inner tolerance (see above); off: the QP tolerance stays qp_rtol (the paper's).
  bool adaptive_qp_tolerance = true;
  double qp_rtol_floor = 1e-12;
  // The inner tolerance follows the outer progress: step k is solved to
  // min(qp_rtol, qp_rtol_per_err · err(k−1)) (not below the floor), so the QP's error in G stays
  // well under err as err falls to tol. 0 turns it off (every step at qp_rtol, the paper's). A run that
  // meets tol with its last QP more than 100× looser than final_step_qp_rtol (it converged abruptly)
  // repeats that step at final_step_qp_rtol before declaring convergence.
  double qp_rtol_per_err = 1e-6;
  // Sizes of the blocks of the state (empty: one block). err(k) is the largest of the blocks'
  // relative changes, so a state made of quantities with different units (Coulomb's slip and
  // normal pressure) converges only when each of them has.
  std::vector<int> blocks;
  // What a failed run's hint may suggest (FixedPointResult::hint): a gentler law only where the
  // coefficient depends on the slip (friction.param); another QP only where it is not the one in use.
  struct HintContext {
    bool slip_dependent_law = true;     // false: a constant coefficient, the map acting on the normal pressure
    bool table_law = false;             // a law given by friction.points (no friction.param)
    bool qp_is_auto = true;             // solver.qp = "auto" (else "ssn" or one of the MPGPs alone)
    bool ill_conditioned_dual = false;  // the stability check warned of cond(Q)
  } hint_context;
};

// v ↦ G'(φ) v, the derivative of G at the φ just evaluated (valid until the next evaluation).
using SlipDerivative = std::function<Eigen::VectorXd(const Eigen::VectorXd& v)>;

// φ ↦ G(φ) predicted from the φ just evaluated without another solve (valid until the next
// evaluation); an empty vector when it cannot predict.
using SlipPrediction = std::function<Eigen::VectorXd(const Eigen::VectorXd& phi)>;

// One evaluation of G: what the Tresca solve reports back.
struct SlipEvaluation {
  Eigen::VectorXd slip;        // G(φ) at the contact nodes
  bool ok = true;              // false when the inner QP failed
  bool qp_broke_down = false;  // it failed on a breakdown (no positive curvature, or not finite), not its limit
  int qp_iterations = 0;
  int hessian_products = 0;
  SlipDerivative derivative;  // empty: G gives no derivative (the frictionless first Coulomb solve, tests)
  SlipPrediction predict;     // empty: G gives no prediction
  // K⁻¹ applications (paper's count) that `derivative` and `predict` have cost so far, a running
  // total (empty: they cost none); the fixed point counts the difference across its calls in n_mult.
  std::function<int()> derivative_products;
};

// How a step's input φᵏ⁻¹ was made from the steps before it (history.csv's `update` column):
// start (φ⁰ = 0), plain (G of the last input), relaxed (Aitken), newton, mixed (Anderson), predicted
// (the fixed point of G's prediction), restart (a plain or relaxed step from the input before a
// rejected Newton or mixed step), repeat (the same
// φ again with the exact QP tolerance, after an inexact step met tol, or with final_step_qp_rtol, after
// a step met tol with its QP more than 100× looser than that).
enum class FixedPointUpdate { Start, Plain, Relaxed, Newton, Mixed, Predicted, Restart, Repeat };
inline constexpr NameTable<FixedPointUpdate, 8> kFixedPointUpdateNames{{{FixedPointUpdate::Start, "start"},
                                                                        {FixedPointUpdate::Plain, "plain"},
                                                                        {FixedPointUpdate::Relaxed, "relaxed"},
                                                                        {FixedPointUpdate::Newton, "newton"},
                                                                        {FixedPointUpdate::Mixed, "mixed"},
                                                                        {FixedPointUpdate::Predicted, "predicted"},
                                                                        {FixedPointUpdate::Restart, "restart"},
                                                                        {FixedPointUpdate::Repeat, "repeat"}}};

struct FixedPointStep {
  int k = 0;
  double err = 0;
  int qp_iterations = 0;
  int n_mult = 0;                                     // cumulative multiplications by K⁻¹ (paper's count)
  double seconds = 0;                                 // wall time of this step
  double qp_rtol = 0;                                 // the QP tolerance this step was solved to
  FixedPointUpdate update = FixedPointUpdate::Start;  // how this step's input was made
};

struct FixedPointResult {
  FixedPointStatus status = FixedPointStatus::IterationLimit;
  std::vector<FixedPointStep> history;
  Eigen::VectorXd phi;  // the last input φ (the final Tresca solve used c(phi))
  // Observed contraction factor q (NaN before three steps) and the a posteriori estimate of the
  // relative distance of the last G(φ) to the fixed point, q/(1 − q)·err (∞ when q >= 1; a bound
  // where q bounds the map's Lipschitz constant, see above).
  double contraction_factor = std::numeric_limits<double>::quiet_NaN();
  double distance_bound = std::numeric_limits<double>::infinity();
  int qp_tolerance_tightenings = 0;  // times the inner tolerance was tightened: against noise, or to the final
                                     // step's after a repeat found the looser one blind
  int plain_fallback_step = 0;       // the step after which an accelerated variant fell back to plain steps (0: never)
  int mixed_steps = 0;               // iterates the accelerated variant took from its tail mixing
  int newton_steps = 0;              // iterates the accelerated variant took from Newton steps
  int predicted_steps = 0;           // iterates it took from the fixed point of G's prediction
  std::string hint;                  // what to try when the status is not "converged"
  int iterations() const { return static_cast<int>(history.size()); }
};

using SlipMap = std::function<SlipEvaluation(const Eigen::VectorXd& phi, double suggested_qp_rtol)>;
using StepObserver = std::function<void(const FixedPointStep&)>;

// The QP tolerance of the last step of a converged run: qp_rtol_per_err · tol (not below the floor,
// nor above qp_rtol); qp_rtol when the inner tolerance does not follow the outer progress. A problem
// solved by one QP (no fixed point) gets this one, since that QP is its whole answer.
double final_step_qp_rtol(const FixedPointSettings& settings, double qp_rtol);

// `qp_rtol` is passed on to G unchanged (exact steps, as in the paper) unless settings.inexact.
FixedPointResult solve_fixed_point(const SlipMap& G, int n_phi, const FixedPointSettings& settings, double qp_rtol,
                                   const StepObserver& observe = {});

}  // namespace contact3d
