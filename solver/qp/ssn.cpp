#include "qp/ssn.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>

#include "linalg/dense_cholesky.hpp"
#include "qp/bordered_newton.hpp"
#include "qp/newton_system.hpp"
#include "qp/reduced_cg.hpp"

namespace contact3d {
namespace {

// ‖gᴾ(λ)‖ for feasible λ, the MPGP stopping measure.
double projected_gradient_norm(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, const Eigen::VectorXd& g) {
  const GradientSplit split = split_gradient(qp, lambda, g);
  return std::sqrt(split.free.squaredNorm() + split.chopped.squaredNorm());
}

// `flops` in products by the m x m Q (2m² flops each).
double flops_in_products(double flops, int m) { return m > 0 ? flops / (2.0 * m * static_cast<double>(m)) : 0.0; }

// Iterative refinement in double (each refinement one product by Q) of `approximate`, a solver of
// the reduced system in single precision or through the bordered factor, until the residual is
// `target` of the right-hand side, or stops falling once below kRefinedResidual (rounding). Where
// the refinement stalls above that (`approximate` too inaccurate: a single factor of an
// ill-conditioned Q cuts the error by only about cond(Q) · ε_single per refinement), conjugate
// gradients preconditioned by `approximate` take over from the best iterate (refine_by_pcg). False
// when neither gets below kRefinedResidual: the caller then takes a more accurate route.
// The target follows the QP's tolerance (newton_refinement_target): on the free thin slab, whose
// equality loop solves its QPs to 1e-12, one fixed 1e-10 left every Newton step short and MPGP
// crawled the rest (h = 0.035: 128 340 products, 42 s; with the target 1 174 products, 2.3 s).
constexpr int kMaxRefinements = 8;
constexpr double kRefinedResidual = 1e-10;
// Preconditioned CG's iterations after a stalled refinement: each costs a product by Q and an
// approximate solve, so 40 stay far below the reduced factorization they spare where the bordered
// route was chosen (its flops were lower by 100 times on the free slab).
constexpr int kMaxPcgIterations = 40;
double newton_refinement_target(double rtol) { return std::min(kRefinedResidual, rtol); }

// Conjugate gradients on the correction A e = r of x (r = b − A x, known), preconditioned by
// `approximate` (flexible: reduced_cg.hpp), to `target` of ‖b‖; true when the residual of x + e,
// recomputed in double at the end (CG's recursive one drifts), gets there or below kRefinedResidual.
template <class ApproximateSolve>
bool refine_by_pcg(const BoxDiscQP& qp, const std::vector<Direction>& d, const ApproximateSolve& approximate,
                   double target, const Eigen::VectorXd& b, const Eigen::VectorXd& r, Eigen::VectorXd& x,
                   int& products) {
  const double b_norm = b.norm();
  Eigen::VectorXd e;  // from zero: no product for its start
  // By reference: `approximate` may hold a factor (LowRankUpdatedSolve), which must not be copied.
  const ReducedPreconditioner precondition = [&approximate](const Eigen::VectorXd& v) {
    return Eigen::VectorXd(approximate(v));
  };
  products += solve_reduced_cg(qp, d, r, target * b_norm, kMaxPcgIterations, e, precondition).iterations;
  x += e;
  const Eigen::VectorXd left = b - reduced_product(qp, d, x);
  ++products;
  return left.allFinite() && left.norm() <= std::max(target, kRefinedResidual) * b_norm;
}

template <class ApproximateSolve>
bool refine_in_double(const BoxDiscQP& qp, const std::vector<Direction>& d, const ApproximateSolve& approximate,
                      double target, Eigen::VectorXd& y, int& products) {
  const Eigen::VectorXd b = y;
  const double b_norm = b.norm();
  Eigen::VectorXd x = approximate(b);
  Eigen::VectorXd best_x, best_r;
  double before = INFINITY;
  for (int it = 0; it <= kMaxRefinements; ++it) {
    const Eigen::VectorXd r = b - reduced_product(qp, d, x);
    ++products;
    if (!r.allFinite()) return false;
    const double left = r.norm();
    if (left < before) best_x = x, best_r = r;
    const bool stalled = left > 0.5 * before || it == kMaxRefinements;
    if (left <= target * b_norm || (stalled && left <= kRefinedResidual * b_norm)) {
      y = x;
      return true;
    }
    if (stalled) break;
    before = left;
    x += approximate(r);
  }
  if (best_x.size() == 0 || !refine_by_pcg(qp, d, approximate, target, b, best_r, best_x, products)) return false;
  y = best_x;
  return true;
}

// M⁻¹ for M = M₀ + CᵀC, given M₀⁻¹ (the bordered factor's solve) and C = A D (the problem's low-rank
// term, reduced_low_rank): Woodbury's M⁻¹b = M₀⁻¹b − Z (I + C Z)⁻¹ C M₀⁻¹b, Z = M₀⁻¹Cᵀ (k_A solves
// once per Newton step). Without a low-rank term, M₀⁻¹ itself.
class LowRankUpdatedSolve {
 public:
  LowRankUpdatedSolve(const BoxDiscQP& qp, const std::vector<Direction>& d, const BorderedNewton& base) : base_(base) {
    if (!qp.has_low_rank()) return;
    C_ = reduced_low_rank(qp, d);
    Z_.resize(C_.cols(), C_.rows());
    for (Eigen::Index j = 0; j < C_.rows(); ++j) Z_.col(j) = base_.solve(C_.row(j).transpose());
    capacitance_.compute(Eigen::MatrixXd::Identity(C_.rows(), C_.rows()) + C_ * Z_);
  }
  bool ok() const { return C_.rows() == 0 || (Z_.allFinite() && capacitance_.info() == Eigen::Success); }
  Eigen::VectorXd operator()(const Eigen::VectorXd& b) const {
    Eigen::VectorXd x = base_.solve(b);
    if (C_.rows() > 0) x -= Z_ * capacitance_.solve(C_ * x);
    return x;
  }

 private:
  const BorderedNewton& base_;
  Eigen::MatrixXd C_, Z_;
  Eigen::LDLT<Eigen::MatrixXd> capacitance_;
};

// The reduced system through the factor of the whole Q (bordered_newton.hpp), where that is cheaper
// than factoring it (refined in double when the factor is single).
bool solve_reduced_bordered(const BoxDiscQP& qp, const std::vector<Direction>& d, double target, Eigen::VectorXd& y,
                            int& products) {
  if (!qp.bordered || !qp.bordered->prepare(d)) return false;
  const LowRankUpdatedSolve solve(qp, d, *qp.bordered);
  if (!solve.ok()) return false;
  if (qp.bordered->exact()) {  // as accurate as a factorization of the reduced matrix in double
    const Eigen::VectorXd x = solve(y);
    if (!x.allFinite()) return false;
    y = x;
    return true;
  }
  const int before = products;
  const bool refined = refine_in_double(qp, d, solve, target, y, products);
  qp.bordered->record_refinement(products - before);  // may switch it to a factor in double
  return refined;
}

// The reduced system solved by a single-precision Cholesky factorization refined in double: for
// large systems (with a single copy of Q, see BoxDiscQP), where the factorization is the cost of a
// Newton step. False when the single factorization fails or the refinement does not converge: the
// caller then solves in double.
bool solve_reduced_in_single(const BoxDiscQP& qp, const std::vector<Direction>& d, double target, Eigen::VectorXd& y,
                             int& products) {
  Eigen::MatrixXf A;
  reduced_matrix(qp, d, A);
  const SingleCholesky chol(std::move(A));
  if (!chol.ok()) return false;
  return refine_in_double(
      qp, d, [&](const Eigen::VectorXd& v) { return chol.solve(v); }, target, y, products);
}

// An inexact Newton step on a matrix-free Q: CG from the current iterate `lambda` to a residual of
// `cg_tolerance` (the caller's forcing term), at most kMaxCgIterations products. The residual is the
// gradient left on the free directions.
constexpr int kMaxCgIterations = 1000;
// The largest forcing term ‖r_CG‖ / ‖gᴾ‖. Measured on the matrix-free dual (n_mult, brick n = 16 /
// slab 1 200 / slab 2 523 multipliers): 0.01 gave 747 / 660 / 1 000; 0.1 gave 820 / 679 / 12 505
// (loose steps used up the hybrid's Newton rounds on the larger slab, MPGP then crawled); 0.001 gave
// 778 / 788 / 1 279.
constexpr double kMaxForcing = 0.01;
// The feasible descent step (SemismoothNewton::feasible_descent_step), where backtracking on ‖F‖
// finds no step: unknowns leaving the feasible set before kEarlyExit of the step are fixed at their
// bound, in at most kMaxExitSolves new solves. Taking it also where backtracking finds only short
// steps (<= 1/8, 1/4, 1/2) cost more on the strip at 5 628 multipliers (13.2, 21.1, 33.9 s against
// 15.4 s): far from the solution its repeated solves fix many cells that later come free again.
constexpr double kEarlyExit = 0.5;
constexpr int kMaxExitSolves = 20;
bool newton_target_by_cg(const BoxDiscQP& qp, const ReducedStep& step, const Eigen::VectorXd& lambda,
                         double cg_tolerance, Eigen::VectorXd& lambda_new, QpResult& result, double& cost,
                         const CgHeartbeat& beat) {
  const Eigen::VectorXd b = restrict_to(step.directions, qp.h - qp.apply(step.lambda_fixed));
  Eigen::VectorXd y = restrict_to(step.directions, lambda);  // CG starts from the current iterate
  const ReducedCgResult cg = solve_reduced_cg(qp, step.directions, b, cg_tolerance, kMaxCgIterations, y, beat);
  result.hessian_products += cg.iterations;
  result.coarse_products += cg.coarse_products;
  result.single_products += cg.single_products;
  cost = cg.iterations;
  lambda_new = step.lambda_fixed + prolong(step.directions, y, qp.size());
  return y.allFinite();
}

// Solves the reduced system for λ⁺ (refined for the QP's tolerance `rtol`); false if its Cholesky
// factorization fails. `products` counts the products by Q of a refinement; `cost` gets the step's
// factorization cost in products (newton_step_cost, or the bordered route's flops), `bordered`
// whether it took that route.
bool newton_target(const BoxDiscQP& qp, const ReducedStep& step, double rtol, Eigen::VectorXd& lambda_new,
                   int& products, double& cost, bool& bordered) {
  const double target = newton_refinement_target(rtol);
  const int k = static_cast<int>(step.directions.size());
  Eigen::VectorXd y = restrict_to(step.directions, qp.h - qp.apply(step.lambda_fixed));
  bordered = k > 0 && solve_reduced_bordered(qp, step.directions, target, y, products);
  cost = bordered ? flops_in_products(qp.bordered->prepare_flops(), qp.size()) : newton_step_cost(k, qp.size());
  if (k > 0 && !bordered && !(qp.Q_single && solve_reduced_in_single(qp, step.directions, target, y, products))) {
    Eigen::MatrixXd A;
    reduced_matrix(qp, step.directions, A);
    const DenseCholesky chol(std::move(A));
    if (!chol.ok()) return false;
    y = chol.solve(y);
  }
  lambda_new = step.lambda_fixed + prolong(step.directions, y, qp.size());
  return y.allFinite();
}

}  // namespace

bool SlowNewtonSteps::record(double step_length, double F_before, double F_after, double cost) {
  const bool full = step_length == 1;
  const bool judged = full || (took_full_step_ && cost > damped_step_budget_);
  in_a_row_ = (judged && F_after > 0.5 * F_before) ? in_a_row_ + 1 : 0;
  took_full_step_ = took_full_step_ || full;
  return in_a_row_ >= 2;
}

double newton_step_cost(int free_directions, int m) {
  const double k = free_directions;
  return flops_in_products(k * k * k / 3.0, m);
}

namespace {

// One solve_ssn() call: the iterate, its gradient and ‖F‖, and each part of a Newton step a method;
// run() reads as the algorithm.
class SemismoothNewton {
 public:
  SemismoothNewton(const BoxDiscQP& qp, Eigen::VectorXd& lambda, const SsnSettings& settings)
      : qp_(qp),
        lambda_(lambda),
        settings_(settings),
        h_norm_(qp.h.norm()),
        tol_(settings.rtol * h_norm_),
        rho_(projection_scale(qp)),
        slow_steps_{settings.damped_step_budget} {}

  QpResult run() {
    if (!prepare_start(qp_, lambda_)) {
      result_.status = QpStatus::Converged;
      return result_;
    }
    g_ = qp_.apply(lambda_) - qp_.h;
    ++result_.hessian_products;
    F_norm_ = residual(lambda_, g_, z_);
    for (int it = 0; it < settings_.max_newton; ++it) {
      if (const std::optional<QpStatus> done = stopping_test()) {
        result_.status = *done;
        return result_;
      }
      heartbeat();
      const double F_before = F_norm_;
      ReducedStep step;
      Eigen::VectorXd target;
      double cost = 0;
      if (!newton_target_from_active_sets(step, target, cost)) break;
      ++result_.iterations;
      ++result_.newton_steps;
      double step_length = 1;
      DampedStep damped = backtrack_towards(target);
      if (damped.length > 0) {
        step_length = damped.length;
        take(std::move(damped));
      } else if (feasible_descent_step(std::move(step), target, cost)) {
        ++result_.feasible_steps;  // judged as a full step below
      } else {
        break;
      }
      if (settings_.stop_when_linear && slow_steps_.record(step_length, F_before, F_norm_, cost)) {
        project(qp_, lambda_);  // a damped step may leave λ just off a circle
        result_.status = QpStatus::IterationLimit;
        return result_;
      }
    }
    return newton_did_not_finish();
  }

 private:
  // ‖F(λ)‖ = ‖λ − P(z)‖, z = λ − ρ g (kept for the next step's active sets).
  double residual(const Eigen::VectorXd& lam, const Eigen::VectorXd& grad, Eigen::VectorXd& z) const {
    z = lam - rho_ * grad;
    Eigen::VectorXd pz = z;
    project(qp_, pz);
    return (lam - pz).norm();
  }

  // MPGP's test at the feasible point P(λ) (λ itself may sit slightly off a circle): converged
  // (λ set to P(λ)), a breakdown (not finite), or nothing (go on).
  std::optional<QpStatus> stopping_test() {
    Eigen::VectorXd lam_f = lambda_;
    project(qp_, lam_f);
    const bool moved = !(lam_f - lambda_).isZero(0);
    const Eigen::VectorXd g_f = moved ? Eigen::VectorXd(qp_.apply(lam_f) - qp_.h) : g_;
    if (moved) ++result_.hessian_products;
    const double pg = projected_gradient_norm(qp_, lam_f, g_f);
    result_.projected_gradient = pg / h_norm_;
    pg_ = pg;
    if (!std::isfinite(pg)) return QpStatus::Breakdown;
    if (pg > tol_) return std::nullopt;
    lambda_ = lam_f;
    return QpStatus::Converged;
  }

  void heartbeat() const {
    if (settings_.progress)
      settings_.progress->beat_each_call(
          [&] { return qp_heartbeat_line("ssn", result_, settings_.rtol, *settings_.progress, settings_.earlier); });
  }

  // Inside a Newton step's CG (matrix-free: each product through the factor of K), its products so far.
  void cg_heartbeat(const ReducedCgResult& cg) const {
    if (!settings_.progress) return;
    settings_.progress->beat_each_call([&] {
      QpResult so_far = result_;
      so_far.hessian_products += cg.iterations;
      return qp_heartbeat_line("ssn", so_far, settings_.rtol, *settings_.progress, settings_.earlier) +
             ", Newton step " + std::to_string(result_.newton_steps + 1) + " by CG: " + std::to_string(cg.iterations) +
             " products";
    });
  }

  // The minimiser over the directions the active sets of z leave free (`target`), those sets
  // (`step`), and the step's cost in products; false where its reduced system cannot be solved
  // (MPGP takes over).
  bool newton_target_from_active_sets(ReducedStep& step, Eigen::VectorXd& target, double& cost) {
    step = split_active_sets(qp_, z_, rho_);
    if (qp_.matrix_free()) {
      ++result_.hessian_products;  // Q λ_fixed
      // Forcing term: the free gradient CG leaves is a fraction of ‖gᴾ‖ that shrinks with it
      // (superlinear near the solution), never asked below what the stopping test needs.
      const double forcing = std::min(kMaxForcing, std::sqrt(pg_ / h_norm_));
      return newton_target_by_cg(qp_, step, lambda_, std::max(forcing * pg_, 0.1 * tol_), target, result_, cost,
                                 [this](const ReducedCgResult& cg) { cg_heartbeat(cg); });
    }
    return solve_reduced(step, target, cost);
  }

  // The minimiser `target` of the reduced system of `step`, its cost added to `cost` (a dense Q).
  bool solve_reduced(const ReducedStep& step, Eigen::VectorXd& target, double& cost) {
    ++result_.hessian_products;  // Q λ_fixed
    bool bordered = false;
    double this_cost = 0;
    if (!newton_target(qp_, step, settings_.rtol, target, result_.hessian_products, this_cost, bordered)) return false;
    result_.bordered_steps += bordered;
    cost += this_cost;
    return true;
  }

  // A trial point of the backtracking on ‖F‖; length 0: none found.
  struct DampedStep {
    double length = 0;
    Eigen::VectorXd lambda, g, z;
    double F = 0;
  };

  // Backtracking on ‖F‖ from λ towards `target` (full steps near the solution: local superlinear
  // convergence): the longest of 1, 1/2, … 1/2¹¹ that lowers ‖F‖, not taken yet.
  DampedStep backtrack_towards(const Eigen::VectorXd& target) {
    const Eigen::VectorXd delta = target - lambda_;
    const Eigen::VectorXd Qd = qp_.apply(delta);
    ++result_.hessian_products;
    DampedStep trial;
    double t = 1;
    for (int ls = 0; ls < 12; ++ls, t *= 0.5) {
      trial.lambda = lambda_ + t * delta;
      trial.g = g_ + t * Qd;
      trial.F = residual(trial.lambda, trial.g, trial.z);
      if (trial.F <= (1 - 1e-4 * t) * F_norm_) {
        trial.length = t;
        return trial;
      }
    }
    return {};
  }

  void take(DampedStep&& step) {
    lambda_ = std::move(step.lambda);
    g_ = std::move(step.g);
    z_ = std::move(step.z);
    F_norm_ = step.F;
  }

  // Where backtracking on ‖F‖ finds no step, the Newton target lies far outside the feasible set:
  // on a thin or slender body (cond(Q) 1e9 – 1e10) the face minimiser moves λ along soft bending
  // modes, pushes hundreds of barely touching cells far below zero, and ‖F‖ rises on the whole
  // segment (the strip of pipeline/scenes/strip.toml at 4 032 multipliers: in its repeat at 1e-10, 949
  // Newton steps found no step, 923 only steps of 1/256 – 1/2048, and MPGP crawled 43 672 iterations,
  // 86 s; with this step 152 iterations, 1.5 s).
  // The feasible descent step fixes the unknowns that leave early (fix_early_exits), solves the
  // reduced system again (at most kMaxExitSolves times, each a bordered update or a factorization),
  // and takes the least S = ½λᵀQλ − hᵀλ on the segment from λ to that target made feasible: feasible
  // by convexity, S lower by construction, one product by Q. `cost` gets the solves' cost. False
  // (nothing moved) where a solve fails or the segment is no descent.
  bool feasible_descent_step(ReducedStep step, Eigen::VectorXd target, double& cost) {
    if (qp_.matrix_free()) return false;  // each solve would be a CG run: not tried there
    EarlyExits exits = fix_early_exits(qp_, lambda_, target, kEarlyExit, step);
    for (int solve = 0; exits.fixed > 0 && solve < kMaxExitSolves; ++solve) {
      if (!solve_reduced(step, target, cost)) return false;
      exits = fix_early_exits(qp_, lambda_, target, kEarlyExit, step);
    }
    Eigen::VectorXd next = lambda_ + exits.first_exit * (target - lambda_);
    project(qp_, next);
    const Eigen::VectorXd delta = next - lambda_;
    const Eigen::VectorXd Qd = qp_.apply(delta);
    ++result_.hessian_products;
    const double slope = g_.dot(delta), curvature = delta.dot(Qd);
    if (!(slope < 0) || !(curvature > 0)) return false;
    const double t = std::min(1.0, -slope / curvature);  // S's least value on the segment
    lambda_ += t * delta;
    g_ += t * Qd;
    F_norm_ = residual(lambda_, g_, z_);
    return true;
  }

  // Newton did not finish: MPGP from the current point (same criterion, same answer), or the
  // iterate handed back to the caller (the hybrid solver) without it.
  QpResult newton_did_not_finish() {
    if (!settings_.fallback_to_mpgp) {
      project(qp_, lambda_);
      result_.status = QpStatus::IterationLimit;
      return result_;
    }
    MpgpSettings fallback;
    fallback.rtol = settings_.rtol;
    fallback.max_iterations = settings_.max_iterations;
    fallback.progress = settings_.progress;
    QpResult result = solve_mpgp(qp_, lambda_, fallback);
    add_counts(result, result_);  // its status, with the Newton steps' work added
    return result;
  }

  const BoxDiscQP& qp_;
  Eigen::VectorXd& lambda_;  // the warm start, and the answer
  const SsnSettings& settings_;
  const double h_norm_, tol_, rho_;
  SlowNewtonSteps slow_steps_;
  QpResult result_;
  Eigen::VectorXd g_, z_;  // Qλ − h and z = λ − ρ g at the iterate
  double F_norm_ = 0, pg_ = 0;
};

}  // namespace

QpResult solve_ssn(const BoxDiscQP& qp, Eigen::VectorXd& lambda, const SsnSettings& settings) {
  return SemismoothNewton(qp, lambda, settings).run();
}

}  // namespace contact3d
