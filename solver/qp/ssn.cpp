#include "qp/ssn.hpp"

#include <cmath>
#include <utility>
#include <vector>

#include "linalg/dense_cholesky.hpp"

namespace contact3d {
namespace {

// ‖gᴾ(λ)‖ for feasible λ, the MPGP stopping measure.
double projected_gradient_norm(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, const Eigen::VectorXd& g) {
  const GradientSplit split = split_gradient(qp, lambda, g);
  return std::sqrt(split.free.squaredNorm() + split.chopped.squaredNorm());
}

// One unknown of the reduced Newton system: λ moves along w_a e_a + w_b e_b (b < 0: a unit
// vector), and `shift` is the diagonal term a sliding disc adds in its tangent direction.
struct Direction {
  int a, b;
  double w_a, w_b, shift;
};

// The Newton step of F(λ) = λ − P(λ − ρ g(λ)) split by the active sets of z = λ − ρ g:
//   λ⁺ = λ_fixed + Σ_k y_k d_k,   (Dᵀ Q D + diag(shift)) y = Dᵀ (h − Q λ_fixed),
// where λ_fixed holds what the step fixes (λ_n = 0 off contact, λ_t = 0 on a point disc, λ_t = c ν
// on a sliding disc, ν = z_t / ‖z_t‖) and the directions d_k are the free unit vectors (normal in
// contact, tangential inside a disc) and the sliding tangents τ ⊥ ν with shift (1 − κ) / (ρ κ),
// κ = c / ‖z_t‖. This is J δ = −F with J = I − D_P + ρ D_P Q (D_P ∈ ∂P(z)) row by row in the
// (ν, τ) frame of each sliding disc, and, unlike J, it is symmetric positive definite.
struct ReducedStep {
  Eigen::VectorXd lambda_fixed;
  std::vector<Direction> directions;
};

ReducedStep split_active_sets(const BoxDiscQP& qp, const Eigen::VectorXd& z, double rho) {
  const int r = qp.r;
  ReducedStep step{Eigen::VectorXd::Zero(z.size()), {}};
  step.directions.reserve(static_cast<std::size_t>(z.size()));
  for (int i = 0; i < r; ++i)
    if (z[i] > 0) step.directions.push_back({i, -1, 1.0, 0.0, 0.0});
  if (!qp.with_friction) return step;
  for (int i = 0; i < r; ++i) {
    const int a = qp.layout().t1(i), b = qp.layout().t2(i);
    const double c = qp.radius[i], zn = std::hypot(z[a], z[b]);
    if (c <= 0) continue;  // a point disc: λ_t = 0
    if (zn <= c) {         // inside the disc
      step.directions.push_back({a, -1, 1.0, 0.0, 0.0});
      step.directions.push_back({b, -1, 1.0, 0.0, 0.0});
      continue;
    }
    const double nu_a = z[a] / zn, nu_b = z[b] / zn, kappa = c / zn;
    step.lambda_fixed[a] = c * nu_a;
    step.lambda_fixed[b] = c * nu_b;
    step.directions.push_back({a, b, -nu_b, nu_a, (1 - kappa) / (rho * kappa)});
  }
  return step;
}

// Dᵀ Q D + diag(shift), lower triangle (column-major, k x k), in double or in single precision.
template <typename Matrix>
void reduced_matrix(const Eigen::MatrixXd& Q, const std::vector<Direction>& d, Matrix& A) {
  using Scalar = typename Matrix::Scalar;
  const int k = static_cast<int>(d.size());
  A.resize(k, k);
  for (int col = 0; col < k; ++col) {
    const Direction& c = d[static_cast<std::size_t>(col)];
    const double* qa = Q.col(c.a).data();
    const double* qb = c.b >= 0 ? Q.col(c.b).data() : nullptr;
    for (int row = col; row < k; ++row) {
      const Direction& e = d[static_cast<std::size_t>(row)];
      double v = c.w_a * (e.w_a * qa[e.a] + (e.b >= 0 ? e.w_b * qa[e.b] : 0.0));
      if (qb) v += c.w_b * (e.w_a * qb[e.a] + (e.b >= 0 ? e.w_b * qb[e.b] : 0.0));
      A(row, col) = static_cast<Scalar>(row == col ? v + c.shift : v);
    }
  }
}

// (Dᵀ Q D + diag(shift)) y with one product by Q in double.
Eigen::VectorXd reduced_product(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::VectorXd& y) {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(qp.size());
  for (std::size_t j = 0; j < d.size(); ++j) {
    v[d[j].a] += d[j].w_a * y[static_cast<Eigen::Index>(j)];
    if (d[j].b >= 0) v[d[j].b] += d[j].w_b * y[static_cast<Eigen::Index>(j)];
  }
  const Eigen::VectorXd Qv = qp.apply(v);
  Eigen::VectorXd out(y.size());
  for (std::size_t j = 0; j < d.size(); ++j) {
    const Direction& e = d[j];
    const auto i = static_cast<Eigen::Index>(j);
    out[i] = e.w_a * Qv[e.a] + (e.b >= 0 ? e.w_b * Qv[e.b] : 0.0) + e.shift * y[i];
  }
  return out;
}

// The reduced system solved by a single-precision Cholesky factorization refined in double (each
// refinement one product by Q): for large systems (with a single copy of Q, see BoxDiscQP), where
// the factorization is the cost of a Newton step. False when the single factorization fails or the
// refinement does not reach kRefinedResidual: the caller then solves in double.
constexpr int kMaxRefinements = 4;
constexpr double kRefinedResidual = 1e-10;
bool solve_reduced_in_single(const BoxDiscQP& qp, const std::vector<Direction>& d, Eigen::VectorXd& y, int& products) {
  Eigen::MatrixXf A;
  reduced_matrix(*qp.Q, d, A);
  const SingleCholesky chol(std::move(A));
  if (!chol.ok()) return false;
  const Eigen::VectorXd b = y;
  Eigen::VectorXd x = chol.solve(b);
  for (int it = 0; it < kMaxRefinements; ++it) {
    const Eigen::VectorXd r = b - reduced_product(qp, d, x);
    ++products;
    if (!r.allFinite()) return false;
    if (r.norm() <= kRefinedResidual * b.norm()) {
      y = x;
      return true;
    }
    x += chol.solve(r);
  }
  return false;
}

// Solves the reduced system for λ⁺; false if its Cholesky factorization fails. `products` counts the
// products by Q of a single-precision solve's refinement.
bool newton_target(const BoxDiscQP& qp, const ReducedStep& step, Eigen::VectorXd& lambda_new, int& products) {
  const int k = static_cast<int>(step.directions.size());
  const Eigen::VectorXd residual = qp.h - qp.apply(step.lambda_fixed);
  Eigen::VectorXd y(k);
  for (int j = 0; j < k; ++j) {
    const Direction& d = step.directions[static_cast<std::size_t>(j)];
    y[j] = d.w_a * residual[d.a] + (d.b >= 0 ? d.w_b * residual[d.b] : 0.0);
  }
  if (k > 0 && !(qp.Q_single && solve_reduced_in_single(qp, step.directions, y, products))) {
    Eigen::MatrixXd A;
    reduced_matrix(*qp.Q, step.directions, A);
    const DenseCholesky chol(std::move(A));
    if (!chol.ok()) return false;
    y = chol.solve(y);
  }
  lambda_new = step.lambda_fixed;
  for (int j = 0; j < k; ++j) {
    const Direction& d = step.directions[static_cast<std::size_t>(j)];
    lambda_new[d.a] += d.w_a * y[j];
    if (d.b >= 0) lambda_new[d.b] += d.w_b * y[j];
  }
  return y.allFinite();
}

}  // namespace

QpResult solve_ssn(const BoxDiscQP& qp, Eigen::VectorXd& lambda, const SsnSettings& settings) {
  QpResult result;
  if (!prepare_start(qp, lambda)) {
    result.status = QpStatus::Converged;
    return result;
  }
  const int m = qp.size();
  const double h_norm = qp.h.norm();
  const Eigen::MatrixXd& Q = *qp.Q;
  const double tol = settings.rtol * h_norm;
  // ρ scales the gradient to the size of λ: 1 / (mean diagonal of Q).
  const double rho = m / std::max(Q.diagonal().sum(), 1e-300);
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
  int slow_steps = 0;
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
    ++result.hessian_products;                                             // Q λ_fixed
    if (!newton_target(qp, step, target, result.hessian_products)) break;  // hand over to MPGP
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
    // Full steps that no longer halve ‖F‖: the active sets are settling a few cells at a time
    // (degenerate cells, λ and the gap both ~0), where MPGP finishes far more cheaply.
    slow_steps = (t == 1 && F_norm > 0.5 * F_before) ? slow_steps + 1 : 0;
    if (settings.stop_when_linear && slow_steps >= 2) {
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
  const int newton = result.iterations, products = result.hessian_products;
  result = solve_mpgp(qp, lambda, fallback);
  result.iterations += newton;
  result.newton_steps = newton;
  result.hessian_products += products;
  return result;
}

}  // namespace contact3d
