#include "qp/ssn.hpp"

#include <cmath>
#include <vector>

#include <Eigen/Dense>

extern "C" {
void dgetrf_(const int* m, const int* n, double* a, const int* lda, int* ipiv, int* info);
void dgetrs_(const char* trans, const int* n, const int* nrhs, const double* a, const int* lda, const int* ipiv,
             double* b, const int* ldb, int* info);
}

namespace contact3d {
namespace {

constexpr int kLapackMin = 400;

// ‖gᴾ(λ)‖ for feasible λ, the MPGP stopping measure.
double projected_gradient_norm(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, const Eigen::VectorXd& g) {
  const GradientSplit split = split_gradient(qp, lambda, g);
  return std::sqrt(split.free.squaredNorm() + split.chopped.squaredNorm());
}

}  // namespace

QpResult solve_ssn(const BoxDiscQP& qp, Eigen::VectorXd& lambda, const SsnSettings& settings) {
  QpResult result;
  const int m = qp.size(), r = qp.r;
  if (lambda.size() != m) lambda = Eigen::VectorXd::Zero(m);
  project(qp, lambda);
  const double h_norm = qp.h.norm();
  if (h_norm == 0) {
    lambda.setZero();
    result.status = QpStatus::Converged;
    return result;
  }
  const Eigen::MatrixXd& Q = *qp.Q;
  const double tol = settings.rtol * h_norm;
  // ρ scales the gradient to the size of λ: 1 / (mean diagonal of Q).
  const double rho = m / std::max(Q.diagonal().sum(), 1e-300);

  Eigen::VectorXd g = qp.apply(lambda) - qp.h;
  ++result.hessian_products;
  auto residual = [&](const Eigen::VectorXd& lam, const Eigen::VectorXd& grad, Eigen::VectorXd& z,
                      Eigen::VectorXd& pz) {
    z = lam - rho * grad;
    pz = z;
    project(qp, pz);
    return (lam - pz).norm();
  };
  Eigen::VectorXd z, pz;
  double F_norm = residual(lambda, g, z, pz);
  Eigen::MatrixXd J(m, m);
  std::vector<int> ipiv(m);
  int m_int = m;
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
    // Generalized Jacobian of F: J = I − D + ρ D Q, D block-diagonal ∂P(z) (0 for an inactive
    // normal or a point disc, I inside, (c/‖z‖)(I − ννᵀ) sliding). Built as Jᵀ = I − D + ρ Q D
    // column by column (Q symmetric, column-major) and solved transposed.
    J.setZero();
    auto add_col = [&](int col, int from, double d) {  // Jᵀ(:, col) += ρ d Q(:, from)
      J.col(col) += (rho * d) * Q.col(from);
    };
    for (int i = 0; i < r; ++i) {
      if (z[i] > 0)
        add_col(i, i, 1.0);
      else
        J(i, i) = 1.0;
    }
    if (qp.with_friction) {
      for (int i = 0; i < r; ++i) {
        const int a = qp.layout().t1(i), b = qp.layout().t2(i);
        const double c = qp.radius[i], zn = std::hypot(z[a], z[b]);
        if (c <= 0) {  // a point disc: λ_t is fixed at 0, D = 0
          J(a, a) += 1;
          J(b, b) += 1;
        } else if (zn <= c) {  // inside the disc: D = I
          add_col(a, a, 1.0);
          add_col(b, b, 1.0);
        } else {  // sliding
          const double sc = c / zn, na = z[a] / zn, nb = z[b] / zn;
          const double D00 = sc * (1 - na * na), D01 = -sc * na * nb, D11 = sc * (1 - nb * nb);
          if (sc > 0) {
            add_col(a, a, D00);
            add_col(a, b, D01);
            add_col(b, a, D01);
            add_col(b, b, D11);
          }
          J(a, a) += 1 - D00;
          J(b, a) += -D01;
          J(a, b) += -D01;
          J(b, b) += 1 - D11;
        }
      }
    }
    // LU of Jᵀ, then J δ = −F with the transposed factor: LAPACK (blocked, threaded BLAS) for
    // large m; Eigen below, where waking BLAS threads costs more than the factorization
    // (measured: n = 8, m = 144, 20x slower with 2 OpenBLAS threads on a busy machine).
    Eigen::VectorXd delta = -(lambda - pz);
    if (m < kLapackMin) {
      delta = J.partialPivLu().transpose().solve(delta);
    } else {
      int info = 0, one = 1;
      dgetrf_(&m_int, &m_int, J.data(), &m_int, ipiv.data(), &info);
      if (info == 0) dgetrs_("T", &m_int, &one, J.data(), &m_int, ipiv.data(), delta.data(), &m_int, &info);
      if (info != 0) break;  // singular Jacobian: hand over to MPGP
    }
    ++result.iterations;
    if (!delta.allFinite()) break;
    // Backtracking on ‖F‖ (full steps near the solution: local superlinear convergence).
    double t = 1;
    bool accepted = false;
    const Eigen::VectorXd Qd = qp.apply(delta);
    ++result.hessian_products;
    Eigen::VectorXd z_try, pz_try;
    for (int ls = 0; ls < 12; ++ls, t *= 0.5) {
      const Eigen::VectorXd lam_try = lambda + t * delta;
      const Eigen::VectorXd g_try = g + t * Qd;
      const double F_try = residual(lam_try, g_try, z_try, pz_try);
      if (F_try <= (1 - 1e-4 * t) * F_norm) {
        lambda = lam_try;
        g = g_try;
        z = z_try;
        pz = pz_try;
        F_norm = F_try;
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
  }
  // Newton did not finish: MPGP from the current point (same criterion, same answer).
  MpgpSettings fallback;
  fallback.rtol = settings.rtol;
  fallback.max_iterations = settings.max_iterations;
  fallback.progress = settings.progress;
  const int newton = result.iterations, products = result.hessian_products;
  result = solve_mpgp(qp, lambda, fallback);
  result.iterations += newton;
  result.hessian_products += products;
  return result;
}

}  // namespace contact3d
