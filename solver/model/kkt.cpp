#include "model/kkt.hpp"

#include <algorithm>
#include <cmath>

#include "base/multiplier_layout.hpp"

namespace contact3d {

double KktResiduals::max() const {
  return std::max({equilibrium, normal_feasibility, normal_complementarity, disc_feasibility, slip_alignment});
}

KktResiduals kkt_residuals(const Eigen::VectorXd& Kw, const Eigen::VectorXd& f, const Eigen::SparseMatrix<double>& B,
                           int r, bool with_friction, const Eigen::VectorXd& radius, const Eigen::VectorXd& w,
                           const Eigen::VectorXd& lambda, const Eigen::VectorXd& h, const Eigen::VectorXd& offset) {
  KktResiduals res;
  auto safe_div = [](double a, double b) { return b > 0 ? a / b : a; };
  const Eigen::VectorXd Btl = B.transpose() * lambda;
  res.equilibrium = safe_div((Kw - f + Btl).norm(), std::max(f.norm(), Btl.norm()));
  if (r == 0) return res;
  Eigen::VectorXd d = B * w;
  if (offset.size() == d.size()) d += offset;
  const double scale_d = std::max(d.norm(), h.norm());
  const double scale_lambda = with_friction ? std::max(lambda.norm(), radius.norm()) : lambda.norm();
  const double scale = scale_lambda * scale_d;
  res.normal_feasibility = safe_div(d.head(r).cwiseMax(0.0).norm(), scale_d);
  res.normal_complementarity = safe_div(std::abs(lambda.head(r).dot(d.head(r))), scale);
  if (!with_friction) return res;
  double excess = 0, gap = 0;
  const MultiplierLayout layout{r, true};
  for (int i = 0; i < r; ++i) {
    const int a = layout.t1(i), b = layout.t2(i);
    const Eigen::Vector2d lt(lambda[a], lambda[b]), dt(d[a], d[b]);
    excess = std::max(excess, lt.norm() - radius[i]);
    gap += radius[i] * dt.norm() - lt.dot(dt);
  }
  res.disc_feasibility = safe_div(std::max(0.0, excess), radius.maxCoeff());
  res.slip_alignment = safe_div(std::abs(gap), scale);
  return res;
}

}  // namespace contact3d
