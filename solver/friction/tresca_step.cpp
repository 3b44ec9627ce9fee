#include "friction/tresca_step.hpp"

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

SlipEvaluation TrescaStep::solve(const Eigen::VectorXd& phi, const Eigen::VectorXd& g, double qp_rtol) {
  radius_ = radii_(phi, g);
  last_qp_ = qp_.solve(radius_, lambda_, qp_rtol);
  Eigen::VectorXd u_face = face_dofs_.scatter(dual_.face_displacement(lambda_));
  SlipEvaluation eval;
  eval.ok = last_qp_.status == QpStatus::Converged && u_face.allFinite();
  eval.qp_iterations = last_qp_.iterations;
  eval.hessian_products = last_qp_.hessian_products + 1;  // + w on Γc (counted as one K⁻¹ solve)
  products_ += eval.hessian_products;
  qp_iterations_ += last_qp_.iterations;
  newton_steps_ += last_qp_.newton_steps;
  single_products_ += last_qp_.single_products;
  eval.slip = face_dofs_.slip(face_, u_face);
  last_face_ = std::move(u_face);
  history_.push_back({lambda_, radius_});
  slip_input_ = phi;
  slip_bound_input_ = g;
  return eval;
}

}  // namespace contact3d
