#include "friction/tresca_step.hpp"

#include <algorithm>

namespace contact3d {

TrescaStep::TrescaStep(const DualProblem& dual, DualQpSolver& qp, const FaceDofs& face_dofs, const ContactFace& face,
                       RadiusRule radii, Eigen::VectorXd slip_bound)
    : dual_(dual),
      qp_(qp),
      face_dofs_(face_dofs),
      face_(face),
      radii_(std::move(radii)),
      slip_bound_(std::move(slip_bound)),
      lambda_(Eigen::VectorXd::Zero(dual.size())) {}

SlipEvaluation TrescaStep::operator()(const Eigen::VectorXd& phi, double qp_rtol) {
  SlipEvaluation eval = solve(phi, slip_bound_, qp_rtol);
  if (eval.ok) {
    eval.derivative = [this](const Eigen::VectorXd& v) {
      return derivative(v, Eigen::VectorXd::Zero(slip_bound_.size())).slip;
    };
    eval.derivative_products = [this] { return sensitivity_products(); };
    eval.predict = [this](const Eigen::VectorXd& phi) { return predict(phi, slip_bound_).slip; };
  }
  return eval;
}

namespace {

// The step t of a difference quotient at x along v: t·v is 1e-7 of the larger of x's and v's sizes.
double difference_step(const Eigen::VectorXd& x, const Eigen::VectorXd& v) {
  const double v_size = v.lpNorm<Eigen::Infinity>();
  return v_size > 0 ? 1e-7 * std::max(x.lpNorm<Eigen::Infinity>(), v_size) / v_size : 0.0;
}

}  // namespace

TrescaStep::Derivative TrescaStep::derivative(const Eigen::VectorXd& v_phi, const Eigen::VectorXd& v_g) {
  // One step for both inputs (their units differ: the smaller of the two blocks' steps).
  const double t_phi = difference_step(slip_input_, v_phi), t_g = difference_step(slip_bound_input_, v_g);
  const double t = t_phi > 0 && t_g > 0 ? std::min(t_phi, t_g) : std::max(t_phi, t_g);
  Derivative out{Eigen::VectorXd::Zero(v_phi.size()), Eigen::VectorXd::Zero(slip_bound_.size())};
  if (!(t > 0)) return out;
  const Eigen::VectorXd dc =
      (radii_((slip_input_ + t * v_phi).cwiseMax(0.0), (slip_bound_input_ + t * v_g).cwiseMax(0.0)) - radius_) / t;
  RadiusSensitivity* S = sensitivity();
  const Eigen::VectorXd dlambda = S ? S->apply(dc) : Eigen::VectorXd();
  count_sensitivity_products(S);
  if (!S || !S->ok()) return out;
  out.normal_pressure = dlambda.head(slip_bound_.size());
  // λ ↦ w is affine: its change along dλ, from one application of K⁻¹ on Γc.
  const Eigen::VectorXd dw = face_displacement(lambda_ + dlambda, S->equality_change()) - last_face_;
  const double s = difference_step(last_face_, dw);
  if (s > 0) out.slip = (face_dofs_.slip(face_, last_face_ + s * dw) - last_slip_) / s;
  return out;
}

RadiusSensitivity* TrescaStep::sensitivity() {
  if (!sensitivity_) {
    sensitivity_.emplace(qp_.radius_sensitivity(lambda_));
    counted_products_ = 0;
  }
  return sensitivity_->ok() ? &*sensitivity_ : nullptr;
}

// In the run's n_mult (and the fixed point's history, through SlipEvaluation::derivative_products):
// the sensitivity's products since the last count and the K⁻¹ application on Γc — kDerivativeProducts
// where the reduced system is factored — or kDerivativeProducts for a try without a sensitivity.
void TrescaStep::count_sensitivity_products(const RadiusSensitivity* S) {
  const int products = S ? 1 + S->products() - counted_products_ : kDerivativeProducts;
  if (S) counted_products_ = S->products();
  products_ += products;
  sensitivity_products_ += products;
}

TrescaStep::Prediction TrescaStep::predict(const Eigen::VectorXd& phi, const Eigen::VectorXd& g) {
  RadiusSensitivity* S = sensitivity();
  const Eigen::VectorXd dlambda =
      S ? S->apply(radii_(phi.cwiseMax(0.0), g.cwiseMax(0.0)) - radius_) : Eigen::VectorXd();
  count_sensitivity_products(S);
  if (!S || !S->ok()) return {};  // none, or its CG did not converge (matrix-free)
  const Eigen::VectorXd lambda = lambda_ + dlambda;
  return {face_dofs_.slip(face_, face_displacement(lambda, S->equality_change())),
          lambda.head(slip_bound_.size()).cwiseMax(0.0)};
}

Eigen::VectorXd TrescaStep::face_displacement(const Eigen::VectorXd& lambda, const Eigen::VectorXd& dmu) const {
  Eigen::VectorXd at_dofs = dual_.face_displacement(lambda);
  if (rigid_face_.cols()) {
    at_dofs -= rigid_face_ * qp_.equality_multiplier();
    if (dmu.size()) at_dofs -= rigid_face_ * dmu;
  }
  return face_dofs_.scatter(at_dofs);
}

SlipEvaluation TrescaStep::solve(const Eigen::VectorXd& phi, const Eigen::VectorXd& g, double qp_rtol) {
  radius_ = radii_(phi, g);
  sensitivity_.reset();
  last_qp_ = qp_.solve(radius_, lambda_, qp_rtol);
  Eigen::VectorXd u_face = face_displacement(lambda_);
  SlipEvaluation eval;
  eval.ok = last_qp_.status == QpStatus::Converged && u_face.allFinite();
  eval.qp_broke_down = last_qp_.status == QpStatus::Breakdown;
  eval.qp_iterations = last_qp_.iterations;
  eval.hessian_products = last_qp_.hessian_products + 1;  // + w on Γc (counted as one K⁻¹ solve)
  products_ += eval.hessian_products;
  qp_iterations_ += last_qp_.iterations;
  newton_steps_ += last_qp_.newton_steps;
  bordered_steps_ += last_qp_.bordered_steps;
  feasible_steps_ += last_qp_.feasible_steps;
  rounding_stops_ += last_qp_.rounding_stops;
  coarse_products_ += last_qp_.coarse_products;
  single_products_ += last_qp_.single_products;
  eval.slip = face_dofs_.slip(face_, u_face);
  last_slip_ = eval.slip;
  last_face_ = std::move(u_face);
  history_.push_back({lambda_, radius_, rigid_face_.cols() ? qp_.equality_multiplier() : Eigen::VectorXd()});
  slip_input_ = phi;
  slip_bound_input_ = g;
  return eval;
}

}  // namespace contact3d
