#include "qp/jacobi_scaling.hpp"

#include <algorithm>
#include <cmath>

#include "linalg/dual_operator.hpp"

namespace contact3d {

namespace {
double inverse_sqrt(double d) { return d > 0 ? 1.0 / std::sqrt(d) : 1.0; }
}  // namespace

JacobiScaledQP::JacobiScaledQP(const BoxDiscQP& qp, bool estimate) : qp_(qp) {
  const Eigen::VectorXd d = qp.diagonal();  // of Q itself: qp is not scaled yet
  const int r = qp.r;
  Eigen::VectorXd& s = qp_.scale;
  s.resize(qp.size());
  for (int i = 0; i < r; ++i) s[i] = inverse_sqrt(d[i]);
  if (qp.with_friction)
    for (int i = 0; i < r; ++i) {
      const int a = qp.layout().t1(i), b = qp.layout().t2(i);
      s[a] = s[b] = inverse_sqrt(std::max(d[a], d[b]));
    }
  qp_.h = s.cwiseProduct(qp.h);
  qp_.q_norm =
      estimate ? 1.05 * estimate_norm(qp_.size(), [this](const Eigen::VectorXd& v) { return qp_.apply(v); }) : 0.0;
}

const BoxDiscQP& JacobiScaledQP::scaled(const Eigen::VectorXd& radius) {
  if (qp_.with_friction) qp_.radius = radius.cwiseQuotient(qp_.scale.segment(qp_.r, qp_.r));
  return qp_;
}

}  // namespace contact3d
