#include "qp/radius_sensitivity.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "qp/bordered_newton.hpp"

namespace contact3d {

RadiusSensitivity::RadiusSensitivity(const BoxDiscQP& qp, const Eigen::VectorXd& solution, bool single_precision,
                                     const Eigen::VectorXd& scale)
    : qp_(qp), scale_(scale), single_precision_(single_precision), nu_(Eigen::VectorXd::Zero(qp.size())) {
  if (qp_.matrix_free()) return;  // its reduced systems need Q's entries: not ok()
  // The active sets of z = λ − ρ g, with the semismooth Newton solver's ρ.
  const double rho = projection_scale(qp_);
  const Eigen::VectorXd z = solution - rho * (qp_.apply(solution) - qp_.h);
  step_ = split_active_sets(qp_, z, rho);
  if (qp_.with_friction)
    for (int i = 0; i < qp_.r; ++i) {
      const int a = qp_.layout().t1(i), b = qp_.layout().t2(i);
      const double c = qp_.radius[i];
      if (c > 0 && (step_.lambda_fixed[a] != 0 || step_.lambda_fixed[b] != 0)) {
        nu_[a] = step_.lambda_fixed[a] / c;
        nu_[b] = step_.lambda_fixed[b] / c;
      }
    }
  if (step_.directions.empty()) {
    ok_ = true;
    return;
  }
  if (qp_.bordered && qp_.bordered->prepare(step_.directions)) {
    bordered_preparation_ = qp_.bordered->preparations();
    ok_ = true;
    return;
  }
  ok_ = factor_reduced_matrix();
}

bool RadiusSensitivity::factor_reduced_matrix() {
  if (single_precision_) {
    Eigen::MatrixXf A;
    reduced_matrix(qp_, step_.directions, A);
    single_factor_.emplace(std::move(A));
    return single_factor_->ok();
  }
  Eigen::MatrixXd A;
  reduced_matrix(qp_, step_.directions, A);
  factor_.emplace(std::move(A));
  return factor_->ok();
}

// Whether our system is still the one the bordered solver holds; a QP solve in between (the
// derivative is asked for after the next evaluation) re-prepares it, and a failure there falls back
// to factoring the reduced matrix.
bool RadiusSensitivity::bordered_ready() {
  if (bordered_preparation_ < 0) return false;
  if (qp_.bordered->preparations() == bordered_preparation_) return true;
  if (qp_.bordered->prepare(step_.directions)) {
    bordered_preparation_ = qp_.bordered->preparations();
    return true;
  }
  bordered_preparation_ = -1;
  ok_ = factor_reduced_matrix();
  return false;
}

// One solve and one step of refinement in double (one product by Q).
bool RadiusSensitivity::solve_reduced(const Eigen::VectorXd& b, Eigen::VectorXd& y) {
  const bool bordered = bordered_ready();
  if (!ok_) return false;
  auto solve = [&](const Eigen::VectorXd& rhs) {
    return bordered ? qp_.bordered->solve(rhs) : factor_ ? factor_->solve(rhs) : single_factor_->solve(rhs);
  };
  y = solve(b);
  y += solve(b - reduced_product(qp_, step_.directions, y));
  return true;
}

// dλ in the problem's variables (dμ of the scaled problem, its radii c / s_t), then mapped back.
Eigen::VectorXd RadiusSensitivity::apply(const Eigen::VectorXd& dc) {
  Eigen::VectorXd dlambda = Eigen::VectorXd::Zero(qp_.size());
  if (!ok_ || !qp_.with_friction) return dlambda;
  for (int i = 0; i < qp_.r; ++i) {
    const int a = qp_.layout().t1(i), b = qp_.layout().t2(i);
    const double dc_i = scale_.size() ? dc[i] / scale_[a] : dc[i];  // the scaled radius is c / s_t
    dlambda[a] = dc_i * nu_[a];
    dlambda[b] = dc_i * nu_[b];
  }
  if (!step_.directions.empty()) {
    Eigen::VectorXd dy;
    if (!solve_reduced(-restrict_to(step_.directions, qp_.apply(dlambda)), dy))
      return Eigen::VectorXd::Zero(qp_.size());
    dlambda += prolong(step_.directions, dy, qp_.size());
  }
  return scale_.size() ? Eigen::VectorXd(dlambda.cwiseProduct(scale_)) : dlambda;
}

}  // namespace contact3d
