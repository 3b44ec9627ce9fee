#include "qp/dual_qp_solver.hpp"

#include <utility>

#include "linalg/dual_operator.hpp"
#include "linalg/symmetric_product.hpp"
#include "qp/hybrid_qp.hpp"
#include "qp/reduced_cg.hpp"
#include "qp/ssn.hpp"

namespace contact3d {

bool uses_single_products(QpPrecision precision, int multipliers) {
  return precision == QpPrecision::Mixed || (precision == QpPrecision::Auto && multipliers >= kMixedPrecisionMinSize);
}

DualQpSolver::DualQpSolver(const DenseView& Q, const Eigen::VectorXd& h, int r, bool with_friction, double q_norm,
                           const QpSettings& settings, std::shared_ptr<DualOperatorFactor> factor)
    : settings_(settings) {
  qp_.Q = DenseViewPtr(Q);
  qp_.h = h;
  qp_.r = r;
  qp_.with_friction = with_friction;
  qp_.radius = Eigen::VectorXd::Zero(r);
  qp_.q_norm = 1.05 * q_norm;  // the estimate is a Rayleigh quotient, from below
  const bool single = uses_single_products(settings.precision, qp_.size());
  if (settings.scaling == QpScaling::Jacobi) jacobi_.emplace(qp_, !single);
  if (single) {
    const BoxDiscQP& solved = jacobi_ ? jacobi_->scaled(qp_.radius) : qp_;
    // Ŝ Q Ŝ has a diagonal of at most 1, so its entries are at most 1 in size: no scale needed in
    // float, and its norm comes from the single copy (half the bytes of the 50 products in double).
    single_scale_ = jacobi_ ? 1.0 : solved.q_norm > 0 ? solved.q_norm : 1.0;
    float* spare = factor && factor->in_single ? factor->in_single->spare_upper() : nullptr;
    if (spare) {
      single_ = upper_triangle_in_single(*solved.Q, single_scale_, solved.scale, spare, qp_.size());
      single_holder_ = factor;
    } else {
      q_single_ = lower_triangle_in_single(*solved.Q, single_scale_, solved.scale);
      single_ = &q_single_;
    }
    if (jacobi_) jacobi_->set_norm(1.05 * estimate_norm(single_, single_scale_));
  }
  if (settings.newton_systems == NewtonSystems::Auto)
    bordered_ = make_bordered_newton(std::move(factor),
                                     jacobi_ ? jacobi_->scale() : Eigen::VectorXd(Eigen::VectorXd::Ones(qp_.size())));
}

DualQpSolver::DualQpSolver(MatrixFreeQ Q, const Eigen::VectorXd& h, int r, bool with_friction, double q_norm,
                           const QpSettings& settings)
    : settings_(settings) {
  settings_.precision = QpPrecision::Double;  // no single copy of Q to factor reduced systems in
  qp_.product = std::move(Q.product);
  if (uses_single_products(settings.precision, static_cast<int>(Q.diagonal.size()))) {
    qp_.single_product = std::move(Q.single_product);
    qp_.single_block_product = std::move(Q.single_block_product);
  }
  qp_.block_product = std::move(Q.block_product);
  qp_.q_diagonal = std::move(Q.diagonal);
  qp_.coarse_group = std::move(Q.coarse_group);
  qp_.lumped = std::move(Q.lumped);
  if (!qp_.coarse_group.empty()) qp_.coarse_products = std::make_shared<CoarseProducts>();
  qp_.h = h;
  qp_.r = r;
  qp_.with_friction = with_friction;
  qp_.radius = Eigen::VectorXd::Zero(r);
  qp_.q_norm = 1.05 * q_norm;  // the estimate is a Rayleigh quotient, from below
  if (settings_.scaling != QpScaling::Jacobi) return;
  // The scaled norm from single products where there are any (half the bytes of 50 products).
  const bool single = static_cast<bool>(qp_.single_product);
  jacobi_.emplace(qp_, !single);
  if (!single) return;
  const BoxDiscQP& scaled = jacobi_->scaled(qp_.radius);
  jacobi_->set_norm(1.05 *
                    estimate_norm(qp_.size(), [&scaled](const Eigen::VectorXd& v) { return scaled.apply_single(v); }));
}

BoxDiscQP DualQpSolver::solved_problem() {
  BoxDiscQP problem = jacobi_ ? jacobi_->scaled(qp_.radius) : qp_;
  if (single_) {
    problem.Q_single = single_;
    problem.single_scale = single_scale_;
  }
  problem.bordered = bordered_.get();
  return problem;
}

RadiusSensitivity DualQpSolver::radius_sensitivity(const Eigen::VectorXd& lambda) {
  const bool single = uses_single_products(settings_.precision, qp_.size());
  if (!jacobi_) return {solved_problem(), lambda, single};
  return {solved_problem(), jacobi_->to_scaled(lambda), single, jacobi_->scale()};
}

QpResult DualQpSolver::solve(const Eigen::VectorXd& radius, Eigen::VectorXd& lambda, double rtol) {
  if (qp_.with_friction) qp_.radius = radius;
  if (lambda.size() != qp_.size()) lambda = Eigen::VectorXd::Zero(qp_.size());  // no warm start
  const BoxDiscQP problem = solved_problem();
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
