#include "model/kkt.hpp"

#include <algorithm>
#include <cmath>

#include "base/multiplier_layout.hpp"

namespace contact3d {

double KktResiduals::max() const {
  return std::max({equilibrium, normal_feasibility, normal_complementarity, disc_feasibility, slip_alignment,
                   normal_cellwise, friction_cellwise});
}

namespace {

// The natural residuals of each cell (see kkt.hpp), into res.normal_cellwise, friction_cellwise, worst_cell.
void cellwise_residuals(int r, bool with_friction, const Eigen::VectorXd& radius, const Eigen::VectorXd& lambda,
                        const Eigen::VectorXd& d, const Eigen::VectorXd& h, KktResiduals& res) {
  const double scale_lambda =
      std::max(lambda.lpNorm<Eigen::Infinity>(), with_friction ? radius.lpNorm<Eigen::Infinity>() : 0.0);
  const double scale_d = std::max(d.lpNorm<Eigen::Infinity>(), h.lpNorm<Eigen::Infinity>());
  if (!(scale_lambda > 0) || !(scale_d > 0)) return;  // no pressure and no motion: nothing to weigh
  const double rho = scale_lambda / scale_d;
  const MultiplierLayout layout{r, with_friction};
  double worst = -1;
  for (int i = 0; i < r; ++i) {
    const double ln = lambda[layout.normal(i)];
    const double normal = std::abs(ln - std::max(0.0, ln + rho * d[layout.normal(i)])) / scale_lambda;
    double friction = 0;
    if (with_friction) {
      const Eigen::Vector2d lt(lambda[layout.t1(i)], lambda[layout.t2(i)]);
      const Eigen::Vector2d z = lt + rho * Eigen::Vector2d(d[layout.t1(i)], d[layout.t2(i)]);
      const double zn = z.norm(), c = std::max(radius[i], 0.0);
      const Eigen::Vector2d projected = zn > c ? Eigen::Vector2d(z * (c / zn)) : z;
      friction = (lt - projected).norm() / scale_lambda;
    }
    res.normal_cellwise = std::max(res.normal_cellwise, normal);
    res.friction_cellwise = std::max(res.friction_cellwise, friction);
    if (std::max(normal, friction) > worst) {
      worst = std::max(normal, friction);
      res.worst_cell = i;
    }
  }
}

}  // namespace

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
  cellwise_residuals(r, with_friction, radius, lambda, d, h, res);
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
