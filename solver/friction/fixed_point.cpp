#include "friction/fixed_point.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include <Eigen/Dense>

namespace contact3d {

std::string to_string(FixedPointStatus s) {
  switch (s) {
    case FixedPointStatus::Converged:
      return "converged";
    case FixedPointStatus::IterationLimit:
      return "iteration_limit";
    case FixedPointStatus::Stagnation:
      return "stagnation";
    case FixedPointStatus::InnerSolverFailed:
      return "inner_solver_failed";
  }
  return "?";
}

namespace {

double relative_change(const Eigen::VectorXd& next, const Eigen::VectorXd& prev) {
  const double denom = next.norm();
  const double diff = (next - prev).norm();
  if (denom == 0) return diff == 0 ? 0.0 : 1.0;
  return diff / denom;
}

// The largest relative change over the blocks (the whole vector when `blocks` is empty).
double relative_change(const Eigen::VectorXd& next, const Eigen::VectorXd& prev, const std::vector<int>& blocks) {
  if (blocks.empty()) return relative_change(next, prev);
  double worst = 0;
  Eigen::Index start = 0;
  for (int size : blocks) {
    worst = std::max(worst, relative_change(next.segment(start, size), prev.segment(start, size)));
    start += size;
  }
  return worst;
}

// Weights that make each block of the state (sizes `blocks`; none: one block) of unit size in G(x):
// 1/‖block of gx‖. Secants and least-squares fits over a state made of quantities with different
// units (Coulomb's slip in m and normal pressure in Pa) then see every block, not only the one with
// the largest numbers.
Eigen::VectorXd block_weights(const std::vector<int>& blocks, const Eigen::VectorXd& gx) {
  Eigen::VectorXd w = Eigen::VectorXd::Ones(gx.size());
  Eigen::Index start = 0;
  for (int size : blocks) {
    const double norm = gx.segment(start, size).norm();
    if (norm > 0) w.segment(start, size).setConstant(1 / norm);
    start += size;
  }
  return w;
}

// Anderson mixing (type II) over the last pairs (x_j, G(x_j)); the least-squares fit of the
// residual differences is weighted per block (block_weights).
class AndersonMixer {
 public:
  AndersonMixer(int depth, std::vector<int> blocks) : depth_(depth), blocks_(std::move(blocks)) {}
  void reset() {
    xs_.clear();
    gs_.clear();
  }
  Eigen::VectorXd next(const Eigen::VectorXd& x, const Eigen::VectorXd& gx) {
    xs_.push_back(x);
    gs_.push_back(gx);
    if (static_cast<int>(xs_.size()) > depth_ + 1) {
      xs_.pop_front();
      gs_.pop_front();
    }
    const int m = static_cast<int>(xs_.size()) - 1;
    mixed_ = false;
    if (m == 0) return gx;
    const Eigen::VectorXd w = block_weights(blocks_, gx);
    const Eigen::VectorXd f = w.cwiseProduct(gx - x);
    Eigen::MatrixXd dF(x.size(), m), dG(x.size(), m);
    for (int j = 0; j < m; ++j) {
      dF.col(j) = w.cwiseProduct((gs_[j + 1] - xs_[j + 1]) - (gs_[j] - xs_[j]));
      dG.col(j) = gs_[j + 1] - gs_[j];
    }
    const Eigen::VectorXd gamma = dF.colPivHouseholderQr().solve(f);
    if (!gamma.allFinite()) {
      reset();
      return gx;
    }
    mixed_ = true;
    return (gx - dG * gamma).cwiseMax(0.0);  // slips and pressures are non-negative
  }
  // Whether the last next() mixed; false when it had no earlier pair (or no fit) and returned G(x).
  bool mixed() const { return mixed_; }

 private:
  int depth_;
  std::vector<int> blocks_;
  std::deque<Eigen::VectorXd> xs_, gs_;
  bool mixed_ = false;
};

// Aitken's dynamic relaxation (Irons & Tuck): x ← x + ω r with r = G(x) − x, and ω from the last
// two residuals, ω ← −ω r₋₁ᵀ(r − r₋₁) / ‖r − r₋₁‖² — the secant step along the residual. It
// lengthens the steps of a slow monotone contraction (ω > 1) and shortens those of an oscillation
// (ω < 1); ω is kept in [0.1, 4] so that one bad secant (the active set of the Tresca problem
// changed between the two residuals) cannot throw the iterate far, and slips stay non-negative.
// The secant fits the one-dimensional model r ≈ (1 − ω(1 − ρ)) r₋₁ along the last residual, so it
// is only used when r is nearly parallel to r₋₁: the same way (a slow contraction) or the opposite
// (an oscillation), |cosine| above 1/2. Otherwise the plain step (ω = 1) is taken and the secant
// re-estimated from the next pair:
// - a secant ≤ 0 says the residual grew along the step — far from the fixed point, e.g. a
//   slip-weakening law from φ⁰ = 0 feeding on itself — where no positive ω is right. (Shrinking such
//   steps to ω = 0.1 instead cost the holed prism with slip weakening 15 steps; with plain steps
//   there it takes 11, and `make robustness` 107 of 110 cases within 12 steps instead of 105.)
//   Where the residuals are then almost parallel (cosine > 0.9) the iterates run away along one
//   direction towards a fixed point further on (the slipping zone grows until the coefficient
//   reaches its floor), and a relaxation that was lengthening the steps (ω > 1) keeps its ω
//   instead of falling back to 1: a wedge with F falling from 1.0 to 0.3 took 15 steps, resetting
//   ω at each of four such steps, and takes 13; no case of `make robustness` changes.
// - residuals at a wider angle (another part of the face started or stopped slipping between them;
//   Coulomb's first step with friction after the frictionless start) say nothing of the rate along
//   r₋₁. Their secant is small because r − r₋₁ is long, and as each new ω is proportional to the
//   last one, the relaxation then crept at ω = 0.1 for several steps (2026-11-26: a split ring with
//   Coulomb friction, 9 steps against 6 with this rule; `make robustness` 832 -> 819 steps in all).
class AitkenRelaxation {
 public:
  explicit AitkenRelaxation(std::vector<int> blocks) : blocks_(std::move(blocks)) {}
  Eigen::VectorXd next(const Eigen::VectorXd& x, const Eigen::VectorXd& gx) {
    const Eigen::VectorXd r = gx - x;
    if (last_residual_.size() == r.size()) omega_ = secant_step(r, gx);
    last_residual_ = r;
    return (x + omega_ * r).cwiseMax(0.0);
  }
  // The plain step x ← G(x) (ω = 1), remembered for the first secant.
  Eigen::VectorXd plain(const Eigen::VectorXd& x, const Eigen::VectorXd& gx) {
    last_residual_ = gx - x;
    omega_ = 1;
    return gx;
  }

 private:
  // The next ω from the residuals r₋₁ and r, in block-weighted form (block_weights, the same weights
  // for both).
  double secant_step(const Eigen::VectorXd& r, const Eigen::VectorXd& gx) const {
    constexpr double kMinCosine = 0.5, kRunawayCosine = 0.9;
    const Eigen::VectorXd w = block_weights(blocks_, gx);
    const Eigen::VectorXd last = w.cwiseProduct(last_residual_), now = w.cwiseProduct(r);
    const Eigen::VectorXd dr = now - last;
    const double dr2 = dr.squaredNorm();
    if (!(dr2 > 0)) return omega_;
    const double cosine = now.dot(last) / (now.norm() * last.norm());
    if (!(std::abs(cosine) > kMinCosine)) return 1.0;  // at a wide angle
    const double secant = -omega_ * last.dot(dr) / dr2;
    if (secant > 0) return std::clamp(secant, 0.1, 4.0);
    // The residual grew along itself: a runaway (cosine > 0.9) keeps the step it has, ω ≥ 1.
    return cosine > kRunawayCosine ? std::max(1.0, omega_) : 1.0;
  }

  std::vector<int> blocks_;
  double omega_ = 1;
  Eigen::VectorXd last_residual_;
};

// An update the accelerated variant tries in place of the relaxation (Newton steps, tail mixing),
// on probation: it is on from the first step `may_start` allows. A step of it (one whose input it
// made: FixedPointStep::update, so the mixing's first step, a plain one, is not judged) that does
// not cut err to `required_ratio` of the err before it fails (a Newton step that only creeps is
// worse than the relaxation); a failed step that raised err is also rejected (the caller goes on
// from the step before it). A failure hands back to the relaxation, and after two the run relaxes
// for good. Each step, judge() comes first (for every update), then use().
class GuardedUpdate {
 public:
  GuardedUpdate(FixedPointUpdate kind, double required_ratio) : kind_(kind), required_ratio_(required_ratio) {}
  // Judges the latest step if this update made it.
  void judge(const std::vector<FixedPointStep>& history) {
    const std::size_t n = history.size();
    const bool judged = on_ && n >= 2 && history[n - 1].update == kind_;
    failed_ = judged && history[n - 1].err > required_ratio_ * history[n - 2].err;
    rejected_ = failed_ && history[n - 1].err > history[n - 2].err;
    if (failed_) {
      on_ = false;
      ++failures_;
      raises_ += rejected_;
    }
  }
  // Whether the next iterate comes from this update (not in the step right after a failure);
  // `allowed` = false turns it off.
  bool use(bool may_start, bool allowed) {
    if (!on_ && !failed_ && failures_ < kMaxFailures && may_start) on_ = true;
    if (!allowed) on_ = false;
    return on_;
  }
  bool rejected() const { return rejected_; }  // the last judge() found a failed step of it that raised err
  int raises() const { return raises_; }       // its failed steps that raised err, so far

 private:
  static constexpr int kMaxFailures = 2;
  FixedPointUpdate kind_;
  double required_ratio_;
  bool on_ = false, failed_ = false, rejected_ = false;
  int failures_ = 0, raises_ = 0;
};

// Predicted steps are judged over a few steps, not one by one: where nodes cross a jump of the law,
// err may rise for a step or two while the crossing settles (the slab with a jump law: err 0.16,
// then 0.31, 0.26, 0.078, 4.8e-3, 5e-6 by predicted steps; rejecting the rise as for a Newton step
// cost it 9 steps more). They go on while one in kPatience of them cuts the run's best err by 30%;
// a prediction that cycles (the slab with a steep law: err 0.021, 0.028, 0.021, 0.028, ...) fails,
// and so does one whose own iterations do not converge. After a failure the next step is the
// relaxation's; after two the run goes on without predictions.
class PredictionGuard {
 public:
  // After each step, before take().
  void observe(const FixedPointStep& step) {
    if (step.update == FixedPointUpdate::Predicted && failures_ < kMaxFailures) {
      if (step.err < 0.7 * best_)
        misses_ = 0;
      else if (++misses_ >= kPatience)
        fail();
    }
    best_ = std::min(best_, step.err);
  }
  // Whether the next step may be a predicted one.
  bool take() {
    const bool paused = paused_;
    paused_ = false;
    return failures_ < kMaxFailures && !paused;
  }
  void fail() {  // also for a prediction whose iterations did not converge
    ++failures_;
    misses_ = 0;
    paused_ = true;
  }

 private:
  static constexpr int kPatience = 3, kMaxFailures = 2;
  double best_ = INFINITY;
  int misses_ = 0, failures_ = 0;
  bool paused_ = false;
};

// Tail steps (Newton or mixed, together) that may raise err before the run relaxes for good. Where
// both kinds raise err, the map is not near a linearization its iterates could fit — on a law with a
// jump, nodes cross the jump back and forth — and every further try costs a rejected step and a
// restart: the split ring with a jump law (results/robustness.md) took Newton, Newton, mixed, mixed
// failures, each followed by a restart, 20 steps; relaxing after the second raise, 16.
constexpr int kMaxTailRaises = 2;

// How much looser than final_step_qp_rtol the QP of a converged run's last step may be: a run that
// converges gradually solves its last step to qp_rtol_per_err · err(k−1) with err(k−1) <= 100 tol (the
// paper's brick: 5e-10 against 1e-10); one that jumps to convergence from a larger err repeats it.
constexpr double kFinalStepSlack = 100;

// A predicted step: the fixed point of G's prediction P (SlipEvaluation::predict: the last solve's
// answer moved along its sensitivity to the radii, the law itself exact), by successive
// approximations y ← y + θ(P(y) − y) from y = G(x) until a change ‖P(y) − y‖ is at most `target`
// (then P(y) is the answer); none when they do not get there within kMaxPredictions (P does not
// contract: a law too steep, or an active set that P cannot follow). θ starts at 1 and halves (down
// to 1/8) each time two consecutive changes point against each other (cosine below −1/2): Coulomb's
// coupling of slip and pressure can make P's plain iterations a two-cycle (the slab, h = 0.08, jump
// law: changes 5.5e-2, 5.7e-2, 5.5e-2, ... for 60 iterations), which the averaging damps. A spreading
// cascade's changes point the same way and keep θ = 1. `predictions` counts the P evaluations;
// `rate` is the ratio of the last two changes, the iterations' contraction where they end (NaN after
// one), an estimate of G's there. Where a slip front spreads node by node, or nodes cross a jump of
// the law and push their neighbours across, P's iterations carry the cascade that G's steps would take
// one solve each for: the slab with a jump law (Coulomb, h = 0.06) crept 20 relaxed steps with err
// between 5e-4 and 1e-2 and took 39; its predicted steps take 7.
constexpr int kMaxPredictions = 60;
std::optional<Eigen::VectorXd> predicted_fixed_point(const SlipPrediction& predict, Eigen::VectorXd y, double target,
                                                     const std::vector<int>& blocks, int& predictions, double& rate) {
  rate = std::numeric_limits<double>::quiet_NaN();
  double last_change = std::numeric_limits<double>::quiet_NaN(), theta = 1;
  Eigen::VectorXd last_step;
  for (predictions = 0; predictions < kMaxPredictions;) {
    Eigen::VectorXd next = predict(y);
    ++predictions;
    if (next.size() != y.size() || !next.allFinite()) return std::nullopt;
    const double change = relative_change(next, y, blocks);
    rate = change / last_change;
    last_change = change;
    if (change <= target) return next;
    Eigen::VectorXd step = next - y;
    if (last_step.size() && step.dot(last_step) < -0.5 * step.norm() * last_step.norm())
      theta = std::max(0.125, 0.5 * theta);
    y += theta * step;
    last_step = std::move(step);
  }
  return std::nullopt;
}

// A Newton step on φ − G(φ) = 0: (I − G'(φ)) δ = G(φ) − φ solved by GMRES (from δ = 0, to 1e-2 of
// the residual or 30 Krylov vectors: an inexact Newton step is enough on a map that is only
// piecewise smooth), each iteration one derivative product. Near the
// fixed point it converges superlinearly where the relaxation's single ω cannot fit the map's
// different rates (a rate q needs the step r/(1 − q), a different one per direction).
// `map_norm` returns ‖G′‖ on the Krylov space, from the Arnoldi relation (I − G′)V = V₊H: the largest
// singular value of [I; 0] − H, a lower estimate of the map's local Lipschitz constant.
Eigen::VectorXd newton_direction(const SlipDerivative& derivative, const Eigen::VectorXd& residual, double& map_norm) {
  constexpr int kMaxKrylov = 30;
  constexpr double kRelativeResidual = 1e-2;
  const double beta = residual.norm();
  Eigen::VectorXd delta = Eigen::VectorXd::Zero(residual.size());
  if (!(beta > 0)) return delta;
  std::vector<Eigen::VectorXd> basis{residual / beta};
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(kMaxKrylov + 1, kMaxKrylov);
  Eigen::VectorXd y;
  for (int j = 0; j < kMaxKrylov; ++j) {
    Eigen::VectorXd w = basis[j] - derivative(basis[j]);
    for (int i = 0; i <= j; ++i) {  // modified Gram–Schmidt
      H(i, j) = w.dot(basis[i]);
      w -= H(i, j) * basis[i];
    }
    H(j + 1, j) = w.norm();
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(j + 2);
    rhs[0] = beta;
    const auto Hj = H.topLeftCorner(j + 2, j + 1);
    y = Hj.colPivHouseholderQr().solve(rhs);
    const double krylov_residual = (rhs - Hj * y).norm();
    if (!(krylov_residual > kRelativeResidual * beta) || !(H(j + 1, j) > 1e-14 * beta)) break;
    basis.push_back(w / H(j + 1, j));
  }
  for (Eigen::Index i = 0; i < y.size(); ++i) delta += y[i] * basis[static_cast<std::size_t>(i)];
  const Eigen::Index k = y.size();
  const Eigen::MatrixXd J = Eigen::MatrixXd::Identity(k + 1, k) - H.topLeftCorner(k + 1, k);
  map_norm = k > 0 ? Eigen::JacobiSVD<Eigen::MatrixXd>(J).singularValues()[0] : 0.0;
  return delta.allFinite() ? delta : Eigen::VectorXd::Zero(residual.size());
}

// The running total of an evaluation's derivative and prediction products (SlipEvaluation).
int products_so_far(const SlipEvaluation& eval) { return eval.derivative_products ? eval.derivative_products() : 0; }

// q from the last three step lengths ‖G(xₖ) − xₖ‖ (the largest of their two ratios: conservative).
double contraction_factor(const std::vector<double>& step_lengths) {
  const std::size_t n = step_lengths.size();
  if (n < 3) return std::numeric_limits<double>::quiet_NaN();
  double q = 0;
  for (std::size_t j = n - 2; j < n; ++j)
    q = std::max(q, step_lengths[j - 1] > 0 ? step_lengths[j] / step_lengths[j - 1] : 0.0);
  return q;
}

// The paper's iteration is kept while each step is under half the one before (the brick: q ≈ 0.07-0.24)
// and, at the rate of the last two steps, it would meet `tol` within kPlainStepsAhead more steps.
// A ratio of 0.5 or more — a slow contraction, or an oscillation that does not shrink — or a
// contraction just under it that still has far to go hands over to the accelerated steps for good.
// Until 2026-11-29 only the ratio counted: the puck with the jump law and Coulomb's bound contracted
// at 0.45-0.48 and took 14 plain steps (now 6); the robustness tables' bodies with q ≈ 0.3-0.4 took
// 10-12. The brick's steps are unchanged: from its third step on it is at most two steps from tol.
constexpr double kPlainStepsAhead = 4;
bool contracts_fast(const std::vector<double>& lengths, double err, double tol) {
  const std::size_t n = lengths.size();
  if (n < 2) return true;
  const double q = lengths[n - 1] / lengths[n - 2];
  if (!(q < 0.5)) return false;
  if (n < 3 || !(err > tol) || !(q > 0)) return true;  // the first ratio is the start's: not a rate yet
  return std::log(tol / err) / std::log(q) <= kPlainStepsAhead;
}

// The iterates still travel when the last residuals r = G(x) − x point the same way (each cosine
// with the one before above 1/2): a slip front spreading node by node (a weakening or jump law on a
// large contact face) keeps err from falling for many steps while the state moves steadily towards
// the fixed point. A map that does not contract cycles instead: its residuals turn against each
// other (cosines near −1 for a two-cycle). The cosines are taken with one set of block weights `w`
// (block_weights of the latest G(x)) for all three, so that each block of the state counts (Coulomb's
// slips beside its pressures); with one block they are the plain cosines.
bool still_travelling(const std::deque<Eigen::VectorXd>& residuals, const Eigen::VectorXd& w) {
  if (residuals.size() < 3) return false;
  for (std::size_t j = 1; j < residuals.size(); ++j) {
    const Eigen::VectorXd a = w.cwiseProduct(residuals[j]), b = w.cwiseProduct(residuals[j - 1]);
    const double norms = a.norm() * b.norm();
    if (!(norms > 0) || a.dot(b) <= 0.5 * norms) return false;
  }
  return true;
}

// err fell in each of the last two steps: the run is converging again, whatever its best err so
// far (a split ring with a slip-weakening law reached err 0.02 before its slip front spread, then
// rose to 0.15 and fell steadily: taken for stagnation, it went on with plain steps, 47 in all).
bool still_falling(const std::vector<FixedPointStep>& history) {
  const std::size_t n = history.size();
  return n >= 3 && history[n - 1].err < history[n - 2].err && history[n - 2].err < history[n - 3].err;
}

std::string format_g(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// err within this factor of the QPs' tolerance is their rounding: a stall there is no verdict on the law.
constexpr double kRoundingFloor = 1e3;

// `best_err`: the smallest err of the run. A stall at the QP solves' rounding (the L-block asked for
// fixed_point_tol = 1e-12 reached 4.5e-12 with QPs to 1e-12 and wandered up to 6e-11) is said as such,
// not as a law too steep for the iteration. `qp_broke_down`: the failed QP of an InnerSolverFailed run broke down.
std::string hint_for(FixedPointStatus status, double q, double final_rtol, double best_err,
                     const FixedPointSettings::HintContext& context, bool qp_broke_down) {
  // An err of 0 is a step whose QP kept its warm start (0 iterations), not a level the iteration reached:
  // a strip with a ramp law stagnated after such steps and was told a tolerance "below about 0" was out of reach.
  const bool at_rounding = best_err > 0 && best_err <= kRoundingFloor * final_rtol;
  if ((status == FixedPointStatus::Stagnation || (status == FixedPointStatus::IterationLimit && !(q < 1))) &&
      at_rounding)
    return "err fell to " + format_g(best_err) + " and then stalled at the rounding of the QP solves (each to " +
           format_g(final_rtol) + "), not for the law: a solver.fixed_point_tol below about " +
           format_g(10 * best_err) + " cannot be reached here; ask for that or more";
  switch (status) {
    case FixedPointStatus::Converged:
      return "";
    case FixedPointStatus::IterationLimit:
      if (std::isnan(q))  // fewer than three steps: no rate observed yet
        return "the iteration limit came before a contraction rate could be observed: raise "
               "solver.fixed_point_max_iter";
      if (!(q < 1)) return hint_for(FixedPointStatus::Stagnation, q, final_rtol, best_err, context, qp_broke_down);
      return "the successive approximations contract slowly (q = " + format_g(q) +
             "): raise solver.fixed_point_max_iter, or try solver.fixed_point = \"aitken\" (relaxation from the start)";
    case FixedPointStatus::Stagnation:
      // A constant coefficient has no slope: Coulomb's map on the normal pressure (a helper's sheared
      // block, ν = 0.4999999, F = 1.5) was told to try "a gentler law (smaller friction.param)".
      return "the map does not contract here (q = " + format_g(q) + ") although each QP was solved to " +
             format_g(final_rtol) + ": " +
             (context.slip_dependent_law
                  ? std::string("the law is too steep for successive approximations at this slip level (the paper's "
                                "convergence needs a small Lipschitz modulus of F); try a gentler law (") +
                        (context.table_law ? "a smaller slope between friction.points" : "smaller friction.param") +
                        "), a finer mesh, or solver.fixed_point = \"aitken\""
                  : std::string("Coulomb's map on the normal pressure contracts only for a small enough coefficient, "
                                "and less as the material nears incompressibility; try solver.fixed_point = "
                                "\"aitken\" or a finer mesh"));
    case FixedPointStatus::InnerSolverFailed: {
      // A breakdown is not cured by more iterations (a helper's steel-on-rubber plate under "mpgp":
      // 212 375 iterations, then a direction of no positive curvature, and the hint said to raise them).
      const std::string other_qp =
          context.qp_is_auto ? "try solver.qp = \"ssn\"" : "go back to solver.qp = \"auto\" (MPGP with Newton steps)";
      return (qp_broke_down ? "the dual QP broke down (a search direction along which Q showed no positive "
                              "curvature, or a value not finite: rounding in an ill-conditioned dual); " +
                                  other_qp
                            : "the dual QP did not converge: raise solver.qp_max_iterations, or " + other_qp) +
             (context.ill_conditioned_dual ? "; Q is ill-conditioned (see the warning), which slows every QP" : "");
    }
  }
  return "";
}

}  // namespace

double final_step_qp_rtol(const FixedPointSettings& settings, double qp_rtol) {
  if (!settings.adaptive_qp_tolerance || !(settings.qp_rtol_per_err > 0)) return qp_rtol;
  return std::min(qp_rtol, std::max(settings.qp_rtol_floor, settings.qp_rtol_per_err * settings.tol));
}

namespace {

// One run of the successive approximations (5.7), with the accelerations FixedPointSettings asks
// for: the state carried from step to step, and each kind of update as a method. run() reads as
// the algorithm: evaluate G at x (one QP, its tolerance tied to the progress), record the step,
// stop where err meets the tolerance (repeating a step solved looser than a final one), tighten the
// QPs against their own noise, judge stagnation, and make the next x.
class FixedPointRun {
 public:
  FixedPointRun(const SlipMap& G, int n_phi, const FixedPointSettings& settings, double qp_rtol,
                const StepObserver& observe)
      : G_(G),
        settings_(settings),
        observe_(observe),
        x_(Eigen::VectorXd::Zero(n_phi)),
        mixer_(settings.anderson_depth, settings.blocks),
        relaxation_(settings.blocks),
        relaxing_(settings.variant == FixedPointVariant::Aitken),
        rtol_(qp_rtol),
        eta_(settings.adaptive_qp_tolerance ? settings.qp_rtol_per_err : 0.0) {}

  FixedPointResult run() {
    for (int k = 1; k <= settings_.max_iterations; ++k) {
      const auto t0 = std::chrono::steady_clock::now();
      const double exact_k = exact_tolerance(k);
      const double rtol_k = step_tolerance(k, exact_k);
      const SlipEvaluation eval = G_(x_, rtol_k);
      const FixedPointStep step = record(k, eval, rtol_k, t0);
      if (!eval.ok) {
        qp_broke_down_ = eval.qp_broke_down;
        if (!restart_after_unsolvable_input(k)) return finish(FixedPointStatus::InnerSolverFailed);
        continue;
      }
      if (step.err <= settings_.tol) {
        if (accepted_as_converged(rtol_k, exact_k, eval.qp_iterations)) return finish(FixedPointStatus::Converged);
        made_by_ = FixedPointUpdate::Repeat;  // the same x again, with a tighter QP
        continue;
      }
      if (step.update == FixedPointUpdate::Repeat) keep_final_tolerance();
      force_final_ = false;
      // Noise shows as a stall in which the warm-started QP hardly moved (a few iterations against
      // the first step's); a stall with a busy QP is the map's own slow contraction.
      const bool qp_idle = eval.qp_iterations <= std::max(5, history()[0].qp_iterations / 20);
      tighten_against_noise(k, step, qp_idle, rtol_k);
      if (stagnates(k, step, qp_idle)) return finish(FixedPointStatus::Stagnation);
      Eigen::VectorXd next = next_iterate(x_, eval, k > 1 && step.err > 2 * history()[k - 2].err);
      previous_x_ = std::move(x_);
      previous_gx_ = eval.slip;
      x_ = std::move(next);
    }
    return finish(FixedPointStatus::IterationLimit);
  }

 private:
  const std::vector<FixedPointStep>& history() const { return result_.history; }

  // This step's exact QP tolerance: rtol, and eta·err(k−1) below it once err has fallen (or the
  // final step's, for a repeated step).
  double exact_tolerance(int k) const {
    if (force_final_) return final_step_qp_rtol(settings_, rtol_);
    if (eta_ > 0 && k > 1)
      return std::clamp(eta_ * history()[k - 2].err, std::min(settings_.qp_rtol_floor, rtol_), rtol_);
    return rtol_;
  }

  // The tolerance the QP is asked for: the exact one, or looser for the inexact variant's early steps.
  double step_tolerance(int k, double exact_k) const {
    if (!settings_.inexact || force_exact_) return exact_k;
    return std::max(exact_k, k == 1 ? 1e-3 : std::min(1e-3, 1e-2 * history()[k - 2].err));
  }

  // The step into the history, its residual G(x) − x into the rate and travel estimates.
  FixedPointStep record(int k, const SlipEvaluation& eval, double rtol_k, std::chrono::steady_clock::time_point t0) {
    n_mult_ += eval.hessian_products + derivative_products_;
    derivative_products_ = 0;
    FixedPointStep step;
    step.k = k;
    step.err = relative_change(eval.slip, x_, settings_.blocks);
    step.qp_iterations = eval.qp_iterations;
    step.n_mult = n_mult_;
    step.qp_rtol = rtol_k;
    step.update = made_by_;
    step.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    result_.history.push_back(step);
    result_.phi = x_;
    if (made_by_ == FixedPointUpdate::Repeat) {  // the same x evaluated more exactly: it refines the last
      residuals_.back() = eval.slip - x_;        // step, not a new one whose length would say q = 1
      step_lengths_.back() = residuals_.back().norm();
    } else {
      residuals_.push_back(eval.slip - x_);
      step_lengths_.push_back(residuals_.back().norm());
    }
    if (residuals_.size() > 3) residuals_.pop_front();
    travelling_ = still_travelling(residuals_, block_weights(settings_.blocks, eval.slip));
    if (observe_) observe_(step);
    return step;
  }

  // err met the tolerance. A run that converges abruptly (err(k−1) large: e.g. Coulomb with every
  // cell sticking, err 1 then 0) met it with its QP at up to qp_rtol, far looser than the last step
  // of a run that converges gradually: the answer would be that loose (the slab with a strong law:
  // u on Γc 0.3% off). Such a step, or one of the inexact variant, is repeated (false) at the exact
  // or the final step's tolerance. So is a step whose QP did not move from its warm start (no iteration)
  // at a tolerance looser than the final step's: its G(x) is the last answer again, err ≈ 0 whatever
  // the fixed point's distance (a thin strip, cond(Q) ≈ 1e9, ramp law: three such steps said err ≈ 1e-13,
  // each right after a repeat that had found 3e-2, 4e-3 at the final tolerance, and the third was taken
  // for convergence with u 1.4% from the answer at tol 1e-8).
  bool accepted_as_converged(double rtol_k, double exact_k, int qp_iterations) {
    const double final_rtol = final_step_qp_rtol(settings_, rtol_);
    const bool loose =
        eta_ > 0 && (rtol_k > kFinalStepSlack * final_rtol || (qp_iterations == 0 && rtol_k > final_rtol));
    if (rtol_k <= exact_k && !loose) return true;
    if (rtol_k > exact_k)
      force_exact_ = true;  // same φ again (x unchanged), now with the exact QP tolerance
    else
      force_final_ = true;  // same φ again, with the final step's tolerance
    return false;
  }

  // A repeated step that found err above the tolerance, where the looser step before it had met it:
  // that QP tolerance could not see the change of the radii (an ill-conditioned Q, whose projected
  // gradient is small long before its multipliers settle), nor would the next steps' looser ones. The
  // rest of the run solves at the final step's tolerance.
  void keep_final_tolerance() {
    const double final_rtol = final_step_qp_rtol(settings_, rtol_);
    if (eta_ == 0 && rtol_ <= final_rtol) return;
    rtol_ = final_rtol;
    eta_ = 0;
    ++result_.qp_tolerance_tightenings;
  }

  // A step that barely moves err may be the QP's noise: the inner tolerance is tightened first.
  void tighten_against_noise(int k, const FixedPointStep& step, bool qp_idle, double rtol_k) {
    const bool stalled = k > 1 && step.err > 0.7 * history()[k - 2].err && qp_idle;
    if (!settings_.adaptive_qp_tolerance || !stalled || rtol_ <= settings_.qp_rtol_floor) return;
    rtol_ = std::max(settings_.qp_rtol_floor, 1e-2 * rtol_k);
    eta_ *= 1e-2;
    ++result_.qp_tolerance_tightenings;
    best_err_ = INFINITY;  // stagnation is judged afresh at the new tolerance
  }

  // No new minimum of err for a window of steps, the iterates not moving steadily one way nor err
  // falling step by step (the minimum may date from before a slip front spread), and not for inner
  // noise: the QP is at its floor, or it is busy (the radii keep changing it). An accelerated
  // variant first falls back to the paper's plain steps, which travel with a slow front that the
  // mixing breaks up; only then is the map itself taken not to contract (true).
  bool stagnates(int k, const FixedPointStep& step, bool qp_idle) {
    if (step.err < best_err_) {
      best_err_ = step.err;
      best_k_ = k;
      return false;
    }
    if (k - best_k_ < settings_.stagnation_window || travelling_ || still_falling(history()) ||
        (settings_.adaptive_qp_tolerance && rtol_ > settings_.qp_rtol_floor && qp_idle))
      return false;
    if (settings_.variant == FixedPointVariant::Plain || result_.plain_fallback_step > 0) return true;
    result_.plain_fallback_step = k;
    best_err_ = INFINITY;
    return false;
  }

  // A step whose input an acceleration made (relaxed, Newton, mixed, predicted) and whose QP failed:
  // the input, off the map's own iterates, asked what no contact force can give — on a body held by
  // contact alone under Coulomb's law, radii F·λ_n from an extrapolated pressure whose friction
  // cannot hold the loads' turn (a cross-shaped block twisted to 97% of its capacity: a predicted
  // input left 7.97% of the torque unbalanced, where the plain steps converge in 14). The run goes on
  // with the paper's plain step from the last input that solved, x = G(x_prev), and plain steps from
  // there (plain_fallback_step); false where there is no such input (the failure is the map's own).
  bool restart_after_unsolvable_input(int k) {
    const bool accelerated_input = made_by_ == FixedPointUpdate::Relaxed || made_by_ == FixedPointUpdate::Newton ||
                                   made_by_ == FixedPointUpdate::Mixed || made_by_ == FixedPointUpdate::Predicted;
    if (!accelerated_input || previous_gx_.size() != x_.size() || result_.plain_fallback_step > 0) return false;
    residuals_.pop_back();  // the failed solve's G(x) − x says nothing of the map
    step_lengths_.pop_back();
    x_ = previous_gx_;
    result_.plain_fallback_step = k;
    made_by_ = FixedPointUpdate::Restart;
    return true;
  }

  // The next input x from x_k and G(x_k), by the variant's update; made_by_ says which.
  Eigen::VectorXd next_iterate(const Eigen::VectorXd& xk, const SlipEvaluation& eval, bool err_grew) {
    const Eigen::VectorXd& gx = eval.slip;
    made_by_ = FixedPointUpdate::Plain;
    if (result_.plain_fallback_step > 0) return gx;  // the mixing stalled: the paper's steps from here on
    switch (settings_.variant) {
      case FixedPointVariant::Plain:
        return gx;
      case FixedPointVariant::Anderson:
        return anderson_step(xk, gx, err_grew);
      case FixedPointVariant::Aitken:
      case FixedPointVariant::Accelerated:
        break;
    }
    if (!relaxing_ && !contracts_fast(step_lengths_, history().back().err, settings_.tol)) relaxing_ = true;
    const bool accelerated = relaxing_ && settings_.variant == FixedPointVariant::Accelerated;
    // The tail: err < tail_err, and the iterates no longer travel one way — the front of slipping
    // nodes has settled and the map is close to its linearization about the fixed point. There a
    // Newton step (where G has a derivative) or Anderson's multisecant fit replaces the relaxation's
    // scalar ω, which cannot fit different rates and an oscillation at once. Before the tail the
    // linearization misleads: Newton steps from the start overshot the front (slab h = 0.08, jump
    // law: 24 steps against 21 relaxed, 14 with Newton in the tail).
    const bool in_tail = history().back().err < settings_.tail_err && !travelling_;
    newton_.judge(history());
    tail_mixing_.judge(history());
    prediction_.observe(history().back());
    const bool tail_allowed = newton_.raises() + tail_mixing_.raises() < kMaxTailRaises;
    // A predicted step first, wherever the run relaxes (not only in the tail: a front's cascade is
    // what it carries), unless a Newton or mixed step was just rejected.
    if (accelerated && settings_.predicted_steps && eval.predict && !newton_.rejected() && !tail_mixing_.rejected() &&
        prediction_.take()) {
      if (std::optional<Eigen::VectorXd> y = predicted_step(xk, eval)) return *y;
      prediction_.fail();
    }
    const bool use_newton = accelerated && settings_.newton && newton_.use(in_tail && eval.derivative, tail_allowed);
    const bool use_mixing = accelerated && !use_newton && tail_mixing_.use(in_tail, tail_allowed);
    // A Newton or mixed step that raised err is rejected: the update that follows starts again from
    // the step before it (x, G(x) of the previous step), not from where the bad step led (the U-shaped
    // footprint with Coulomb and a steep law: a Newton step to err 0.6 left the relaxation drifting
    // for 20 steps). A rejected Newton step also shrinks the trust region: later ones are cut to half
    // its length relative to the plain step (as ω <= 4 bounds the relaxation's).
    const bool rejected = newton_.rejected() || tail_mixing_.rejected();
    if (newton_.rejected()) newton_trust_ = 0.5 * last_newton_ratio_;
    if (trust_cut_a_good_newton_step()) newton_trust_ *= 2;
    const Eigen::VectorXd& x0 = rejected ? previous_x_ : xk;
    const Eigen::VectorXd& g0 = rejected ? previous_gx_ : gx;
    if (use_newton) return newton_step(xk, eval);
    if (use_mixing) return mixed_step(x0, g0, rejected);
    return relaxed_step(x0, g0, rejected);
  }

  Eigen::VectorXd anderson_step(const Eigen::VectorXd& xk, const Eigen::VectorXd& gx, bool err_grew) {
    if (err_grew) mixer_.reset();  // safeguard
    Eigen::VectorXd next = mixer_.next(xk, gx);
    made_by_ = mixer_.mixed() ? FixedPointUpdate::Mixed : FixedPointUpdate::Plain;
    return next;
  }

  // The fixed point of G's prediction from the QP's sensitivity to the radii (the law exact), to
  // 1e-2 of err or a tenth of the tolerance; none where the prediction does not converge.
  std::optional<Eigen::VectorXd> predicted_step(const Eigen::VectorXd& xk, const SlipEvaluation& eval) {
    int predictions = 0;
    const double target = std::max(0.1 * settings_.tol, 1e-2 * history().back().err);
    double rate = 0;
    const int products_before = products_so_far(eval);
    std::optional<Eigen::VectorXd> y =
        predicted_fixed_point(eval.predict, eval.slip, target, settings_.blocks, predictions, rate);
    derivative_products_ += products_so_far(eval) - products_before;
    if (!y) return std::nullopt;
    note_tail_start();
    prediction_rate_ = std::isnan(rate) ? 0.0 : rate;
    relaxation_.plain(xk, eval.slip);  // the relaxation's secant starts afresh should the predictions stop
    mixer_.reset();
    ++result_.predicted_steps;
    made_by_ = FixedPointUpdate::Predicted;
    return y->cwiseMax(0.0);
  }

  // Whether the last step was a Newton step that the trust region cut and that cut err anyway (judged and
  // kept): the region then grows again. Without it a region halved after one rejected step stayed so for the
  // rest of the run, and every later Newton step went half the way: a Coulomb strip (cond(Q) 8e9, ramp
  // law, fixed_point_tol 1e-8) cut err by exactly one half per step for 12 steps after a rejection.
  bool trust_cut_a_good_newton_step() const {
    const std::size_t n = history().size();
    if (n < 2 || history()[n - 1].update != FixedPointUpdate::Newton || newton_.rejected()) return false;
    const bool capped = std::isfinite(newton_trust_) && last_newton_ratio_ >= (1 - 1e-9) * newton_trust_;
    return capped && history()[n - 1].err < history()[n - 2].err;
  }

  // A Newton step on x − G(x) = 0 from G's derivative, within the trust region.
  Eigen::VectorXd newton_step(const Eigen::VectorXd& xk, const SlipEvaluation& eval) {
    const Eigen::VectorXd residual = eval.slip - xk;
    note_tail_start();
    const int products_before = products_so_far(eval);
    Eigen::VectorXd delta = newton_direction(eval.derivative, residual, newton_map_norm_);
    if (delta.norm() > newton_trust_ * residual.norm()) delta *= newton_trust_ * residual.norm() / delta.norm();
    last_newton_ratio_ = delta.norm() / residual.norm();
    derivative_products_ += products_so_far(eval) - products_before;
    relaxation_.plain(xk, eval.slip);  // the relaxation's secant starts afresh should Newton stop
    mixer_.reset();
    ++result_.newton_steps;
    made_by_ = FixedPointUpdate::Newton;
    return (xk + delta).cwiseMax(0.0);
  }

  // Anderson mixing in the tail, from (x0, g0): the step before a rejected one, else this one.
  Eigen::VectorXd mixed_step(const Eigen::VectorXd& x0, const Eigen::VectorXd& g0, bool rejected) {
    note_tail_start();
    if (rejected) mixer_.reset();
    relaxation_.plain(x0, g0);
    Eigen::VectorXd next = mixer_.next(x0, g0);
    made_by_ = mixer_.mixed() ? FixedPointUpdate::Mixed
               : rejected     ? FixedPointUpdate::Restart
                              : FixedPointUpdate::Plain;
    if (mixer_.mixed()) ++result_.mixed_steps;
    return next;
  }

  // Aitken's relaxation once the plain steps contract slowly, else the plain step, from (x0, g0).
  Eigen::VectorXd relaxed_step(const Eigen::VectorXd& x0, const Eigen::VectorXd& g0, bool rejected) {
    mixer_.reset();
    if (rejected) {
      made_by_ = FixedPointUpdate::Restart;
      return relaxation_.plain(x0, g0);
    }
    made_by_ = relaxing_ ? FixedPointUpdate::Relaxed : FixedPointUpdate::Plain;
    return relaxing_ ? relaxation_.next(x0, g0) : relaxation_.plain(x0, g0);
  }

  // Before the first Newton, mixed or predicted step: the rate the map showed until then.
  void note_tail_start() {
    if (result_.newton_steps + result_.mixed_steps + result_.predicted_steps > 0) return;
    const double q = contraction_factor(step_lengths_);
    tail_start_q_ = std::isnan(q) ? 0.0 : q;
  }

  FixedPointResult finish(FixedPointStatus status) {
    result_.status = status;
    result_.contraction_factor = contraction_factor(step_lengths_);
    // Both are 0 without a tail; a q not observed yet (NaN, fewer than three steps) stays NaN.
    result_.contraction_factor =
        std::max({result_.contraction_factor, tail_start_q_, newton_map_norm_, prediction_rate_});
    const double q = result_.contraction_factor, err = result_.history.back().err;
    result_.distance_bound = status == FixedPointStatus::Converged && result_.history.size() == 1 ? err
                             : q < 1                                                              ? q / (1 - q) * err
                                     : std::numeric_limits<double>::infinity();
    double best_err = err;
    for (const auto& step : result_.history) best_err = std::min(best_err, step.err);
    result_.hint = hint_for(status, q, rtol_, best_err, settings_.hint_context, qp_broke_down_);
    return std::move(result_);  // the run ends here
  }

  const SlipMap& G_;
  const FixedPointSettings& settings_;
  const StepObserver& observe_;
  FixedPointResult result_;
  Eigen::VectorXd x_;                         // the current input φ
  Eigen::VectorXd previous_x_, previous_gx_;  // the step before the current one: x, G(x)
  AndersonMixer mixer_;
  AitkenRelaxation relaxation_;
  bool relaxing_;  // accelerated: from the first slow step on
  // Newton steps must cut err by 30% (near a fixed point they do far better; where the relaxation
  // creeps, it cuts 10-20% a step); mixed steps must not raise it. Until 2026-11-27 Newton steps had to
  // halve err: a step from 0.061 to 0.033 then counted as failed and the next was a plain one, and the
  // robustness tables (336 cases) took 1233 -> 1229 (Tresca) and 1251 -> 1246 (Coulomb) steps with 0.7.
  GuardedUpdate newton_{FixedPointUpdate::Newton, 0.7}, tail_mixing_{FixedPointUpdate::Mixed, 1.0};
  PredictionGuard prediction_;
  double newton_trust_ = INFINITY, last_newton_ratio_ = 0;  // ‖δ‖ / ‖G(x) − x‖ allowed, and of the last step
  // Newton, mixed and predicted steps contract far faster than the map itself, so their step lengths
  // say nothing of its Lipschitz constant: the a posteriori bound takes the larger of the steps' q, the
  // q observed before the first of them (relaxed or plain steps) and ‖G′‖ of the last Newton step.
  // Predicted steps add the rate of the last prediction's own iterations (the split ring with a jump
  // law: they end at err 7.5e-5, 1.0e-3 from the fixed point, where the steps' lengths alone gave
  // q = 0.12 and a bound of 1e-5).
  double tail_start_q_ = 0, newton_map_norm_ = 0, prediction_rate_ = 0;
  std::vector<double> step_lengths_;
  std::deque<Eigen::VectorXd> residuals_;               // the last three G(x) − x
  bool travelling_ = false;                             // still_travelling(residuals_) after the latest step
  int derivative_products_ = 0;                         // K⁻¹ applications of the Newton steps' derivative products
  FixedPointUpdate made_by_ = FixedPointUpdate::Start;  // how the next input x is made (next_iterate sets it)
  int n_mult_ = 0;
  double best_err_ = INFINITY;
  int best_k_ = 0;
  double rtol_;                 // the exact-step QP tolerance; tightened against inner noise
  bool qp_broke_down_ = false;  // the last failed QP broke down (for the hint)
  double eta_;                  // rtol_k <= eta·err(k−1)
  bool force_exact_ = false;    // an inexact step met tol: repeat it with the exact QP tolerance
  bool force_final_ = false;    // a step met tol with its QP far looser than a final step's: repeat it
};

}  // namespace

FixedPointResult solve_fixed_point(const SlipMap& G, int n_phi, const FixedPointSettings& settings, double qp_rtol,
                                   const StepObserver& observe) {
  return FixedPointRun(G, n_phi, settings, qp_rtol, observe).run();
}

}  // namespace contact3d
