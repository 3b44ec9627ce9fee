#include "qp/ssn.hpp"

#include <algorithm>
#include <cmath>
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
// `target` of the right-hand side, or stops falling once below kRefinedResidual (rounding). False
// when it does not get below kRefinedResidual: the caller then takes a more accurate route.
// The target follows the QP's tolerance (newton_refinement_target): on the free thin slab, whose
// equality loop solves its QPs to 1e-12, one fixed 1e-10 left every Newton step short and MPGP
// crawled the rest (h = 0.035: 128 340 products, 42 s; with the target 1 174 products, 2.3 s).
constexpr int kMaxRefinements = 8;
constexpr double kRefinedResidual = 1e-10;
double newton_refinement_target(double rtol) { return std::min(kRefinedResidual, rtol); }
template <class ApproximateSolve>
bool refine_in_double(const BoxDiscQP& qp, const std::vector<Direction>& d, const ApproximateSolve& approximate,
                      double target, Eigen::VectorXd& y, int& products) {
  const Eigen::VectorXd b = y;
  const double b_norm = b.norm();
  Eigen::VectorXd x = approximate(b);
  double before = INFINITY;
  for (int it = 0; it <= kMaxRefinements; ++it) {
    const Eigen::VectorXd r = b - reduced_product(qp, d, x);
    ++products;
    if (!r.allFinite()) return false;
    const double left = r.norm();
    const bool stalled = left > 0.5 * before || it == kMaxRefinements;
    if (left <= target * b_norm || (stalled && left <= kRefinedResidual * b_norm)) {
      y = x;
      return true;
    }
    if (stalled) return false;
    before = left;
    x += approximate(r);
  }
  return false;
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
  } else if (!refine_in_double(qp, d, solve, target, y, products)) {
    return false;
  }
  return true;
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
bool newton_target_by_cg(const BoxDiscQP& qp, const ReducedStep& step, const Eigen::VectorXd& lambda,
                         double cg_tolerance, Eigen::VectorXd& lambda_new, QpResult& result, double& cost) {
  const Eigen::VectorXd b = restrict_to(step.directions, qp.h - qp.apply(step.lambda_fixed));
  Eigen::VectorXd y = restrict_to(step.directions, lambda);  // CG starts from the current iterate
  const ReducedCgResult cg = solve_reduced_cg(qp, step.directions, b, cg_tolerance, kMaxCgIterations, y);
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

QpResult solve_ssn(const BoxDiscQP& qp, Eigen::VectorXd& lambda, const SsnSettings& settings) {
  QpResult result;
  if (!prepare_start(qp, lambda)) {
    result.status = QpStatus::Converged;
    return result;
  }
  const double h_norm = qp.h.norm();
  const double tol = settings.rtol * h_norm;
  const double rho = projection_scale(qp);
  Eigen::VectorXd g = qp.apply(lambda) - qp.h;
  ++result.hessian_products;
  auto residual = [&](const Eigen::VectorXd& lam, const Eigen::VectorXd& grad, Eigen::VectorXd& z) {
    z = lam - rho * grad;
    Eigen::VectorXd pz = z;
    project(qp, pz);
    return (lam - pz).norm();
  };
  Eigen::VectorXd z;
  double F_norm = residual(lambda, g, z);
  Eigen::VectorXd target;
  SlowNewtonSteps slow_steps{settings.damped_step_budget};
  for (int it = 0; it < settings.max_newton; ++it) {
    // Stopping test at the feasible point P(λ) (λ itself may sit slightly off a circle).
    Eigen::VectorXd lam_f = lambda;
    project(qp, lam_f);
    const bool moved = !(lam_f - lambda).isZero(0);
    const Eigen::VectorXd g_f = moved ? Eigen::VectorXd(qp.apply(lam_f) - qp.h) : g;
    if (moved) ++result.hessian_products;
    const double pg = projected_gradient_norm(qp, lam_f, g_f);
    result.projected_gradient = pg / h_norm;
    if (!std::isfinite(pg)) {
      result.status = QpStatus::Breakdown;
      return result;
    }
    if (pg <= tol) {
      lambda = lam_f;
      result.status = QpStatus::Converged;
      return result;
    }
    if (settings.progress)
      settings.progress->beat([&] { return qp_heartbeat_line("ssn", result, settings.rtol, *settings.progress); });
    const double F_before = F_norm;
    const ReducedStep step = split_active_sets(qp, z, rho);
    ++result.hessian_products;  // Q λ_fixed
    double cost = 0;
    bool bordered = false;
    if (qp.matrix_free()) {
      // Forcing term: the free gradient CG leaves is a fraction of ‖gᴾ‖ that shrinks with it
      // (superlinear near the solution), never asked below what the stopping test needs.
      const double forcing = std::min(kMaxForcing, std::sqrt(pg / h_norm));
      if (!newton_target_by_cg(qp, step, lambda, std::max(forcing * pg, 0.1 * tol), target, result, cost)) break;
    } else if (!newton_target(qp, step, settings.rtol, target, result.hessian_products, cost, bordered)) {
      break;  // hand over to MPGP
    }
    result.bordered_steps += bordered;
    ++result.iterations;
    ++result.newton_steps;
    const Eigen::VectorXd delta = target - lambda;
    // Backtracking on ‖F‖ (full steps near the solution: local superlinear convergence).
    double t = 1;
    bool accepted = false;
    const Eigen::VectorXd Qd = qp.apply(delta);
    ++result.hessian_products;
    Eigen::VectorXd z_try;
    for (int ls = 0; ls < 12; ++ls, t *= 0.5) {
      const Eigen::VectorXd lam_try = lambda + t * delta;
      const Eigen::VectorXd g_try = g + t * Qd;
      const double F_try = residual(lam_try, g_try, z_try);
      if (F_try <= (1 - 1e-4 * t) * F_norm) {
        lambda = lam_try;
        g = g_try;
        z = z_try;
        F_norm = F_try;
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
    const bool slow = slow_steps.record(t, F_before, F_norm, cost);
    if (settings.stop_when_linear && slow) {
      project(qp, lambda);  // a damped step may leave λ just off a circle
      result.status = QpStatus::IterationLimit;
      return result;
    }
  }
  // Newton did not finish: MPGP from the current point (same criterion, same answer).
  if (!settings.fallback_to_mpgp) {
    project(qp, lambda);
    result.status = QpStatus::IterationLimit;
    return result;
  }
  MpgpSettings fallback;
  fallback.rtol = settings.rtol;
  fallback.max_iterations = settings.max_iterations;
  fallback.progress = settings.progress;
  const int newton = result.iterations, products = result.hessian_products, bordered_steps = result.bordered_steps;
  const int coarse_products = result.coarse_products;
  result = solve_mpgp(qp, lambda, fallback);
  result.iterations += newton;
  result.newton_steps = newton;
  result.bordered_steps = bordered_steps;
  result.coarse_products = coarse_products;
  result.hessian_products += products;
  return result;
}

}  // namespace contact3d
