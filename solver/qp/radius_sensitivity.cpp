#include "qp/radius_sensitivity.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace contact3d {

RadiusSensitivity::RadiusSensitivity(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, bool single_precision)
    : qp_(qp), nu_(Eigen::VectorXd::Zero(qp.size())) {
  // The active sets of z = λ − ρ g, with the semismooth Newton solver's ρ.
  const double rho = projection_scale(qp);
  const Eigen::VectorXd z = lambda - rho * (qp.apply(lambda) - qp.h);
  step_ = split_active_sets(qp, z, rho);
  if (qp.with_friction)
    for (int i = 0; i < qp.r; ++i) {
      const int a = qp.layout().t1(i), b = qp.layout().t2(i);
      const double c = qp.radius[i];
      if (c > 0 && (step_.lambda_fixed[a] != 0 || step_.lambda_fixed[b] != 0)) {
        nu_[a] = step_.lambda_fixed[a] / c;
        nu_[b] = step_.lambda_fixed[b] / c;
      }
    }
  if (step_.directions.empty()) {
    ok_ = true;
    return;
  }
  if (single_precision) {
    Eigen::MatrixXf A;
    reduced_matrix(qp, step_.directions, A);
    single_factor_.emplace(std::move(A));
    ok_ = single_factor_->ok();
  } else {
    Eigen::MatrixXd A;
    reduced_matrix(qp, step_.directions, A);
    factor_.emplace(std::move(A));
    ok_ = factor_->ok();
  }
}

// One solve and one step of refinement in double (one product by Q).
Eigen::VectorXd RadiusSensitivity::solve_reduced(const Eigen::VectorXd& b) const {
  auto solve = [&](const Eigen::VectorXd& rhs) { return factor_ ? factor_->solve(rhs) : single_factor_->solve(rhs); };
  Eigen::VectorXd y = solve(b);
  y += solve(b - reduced_product(qp_, step_.directions, y));
  return y;
}

Eigen::VectorXd RadiusSensitivity::apply(const Eigen::VectorXd& dc) const {
  Eigen::VectorXd dlambda = Eigen::VectorXd::Zero(qp_.size());
  if (!ok_ || !qp_.with_friction) return dlambda;
  for (int i = 0; i < qp_.r; ++i) {
    const int a = qp_.layout().t1(i), b = qp_.layout().t2(i);
    dlambda[a] = dc[i] * nu_[a];
    dlambda[b] = dc[i] * nu_[b];
  }
  if (step_.directions.empty()) return dlambda;
  const Eigen::VectorXd dy = solve_reduced(-restrict_to(step_.directions, qp_.apply(dlambda)));
  return dlambda + prolong(step_.directions, dy, qp_.size());
}

}  // namespace contact3d
