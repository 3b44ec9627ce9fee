#include "qp/dual_qp_solver.hpp"

#include "qp/hybrid_qp.hpp"
#include "qp/ssn.hpp"

namespace contact3d {

DualQpSolver::DualQpSolver(const Eigen::MatrixXd& Q, const Eigen::VectorXd& h, int r, bool with_friction, double q_norm,
                           const QpSettings& settings)
    : settings_(settings) {
  qp_.Q = &Q;
  qp_.h = h;
  qp_.r = r;
  qp_.with_friction = with_friction;
  qp_.radius = Eigen::VectorXd::Zero(r);
  qp_.q_norm = 1.05 * q_norm;  // the estimate is a Rayleigh quotient, from below
  if (settings.scaling == QpScaling::Jacobi) jacobi_.emplace(qp_);
}

QpResult DualQpSolver::solve(const Eigen::VectorXd& radius, Eigen::VectorXd& lambda, double rtol) {
  if (qp_.with_friction) qp_.radius = radius;
  const BoxDiscQP& problem = jacobi_ ? jacobi_->scaled(qp_.radius) : qp_;
  Eigen::VectorXd x = jacobi_ ? jacobi_->to_scaled(lambda) : lambda;
  QpResult result;
  if (progress_) progress_->restart();
  if (settings_.variant == QpVariant::Auto) {
    HybridSettings hybrid;
    hybrid.rtol = rtol;
    hybrid.max_iterations = settings_.max_iterations;
    hybrid.progress = progress_;
    result = solve_hybrid(problem, x, hybrid);
  } else if (settings_.variant == QpVariant::Ssn) {
    SsnSettings ssn;
    ssn.rtol = rtol;
    ssn.max_iterations = settings_.max_iterations;
    ssn.progress = progress_;
    result = solve_ssn(problem, x, ssn);
  } else {
    MpgpSettings mpgp;
    mpgp.rtol = rtol;
    mpgp.max_iterations = settings_.max_iterations;
    mpgp.progress = progress_;
    mpgp.expansion =
        settings_.variant == QpVariant::MpgpProjectedCG ? ExpansionKind::ProjectedCG : ExpansionKind::FullGradient;
    result = solve_mpgp(problem, x, mpgp);
  }
  lambda = jacobi_ ? jacobi_->from_scaled(x) : x;
  return result;
}

}  // namespace contact3d
