#include "qp/box_disc_qp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "linalg/symmetric_product.hpp"

namespace contact3d {
namespace {
constexpr double kActiveRelTol = 1e-12;

// out += AᵀA V: the operator's low-rank term (none when A has no rows), in double.
template <class Dense>
Dense with_low_rank(Dense out, const Eigen::MatrixXd& A, const Dense& V) {
  if (A.rows() > 0) out.noalias() += A.transpose() * (A * V);
  return out;
}
}  // namespace

Eigen::VectorXd BoxDiscQP::apply(const Eigen::VectorXd& v) const {
  const auto Q_times = [this](const Eigen::VectorXd& x) { return Q ? symmetric_product(*Q, x) : product(x); };
  if (scale.size() == 0) return with_low_rank(Q_times(v), low_rank, v);
  return with_low_rank(Eigen::VectorXd(scale.cwiseProduct(Q_times(scale.cwiseProduct(v)))), low_rank, v);
}

Eigen::MatrixXd BoxDiscQP::apply_block(const Eigen::MatrixXd& V) const {
  if (!Q && block_product) {
    if (scale.size() == 0) return with_low_rank(block_product(V), low_rank, V);
    return with_low_rank(Eigen::MatrixXd(scale.asDiagonal() * block_product(scale.asDiagonal() * V)), low_rank, V);
  }
  if (Q) {
    if (scale.size() == 0) return with_low_rank(symmetric_block_product(*Q, V), low_rank, V);
    return with_low_rank(
        Eigen::MatrixXd(scale.asDiagonal() * symmetric_block_product(*Q, Eigen::MatrixXd(scale.asDiagonal() * V))),
        low_rank, V);
  }
  Eigen::MatrixXd out(V.rows(), V.cols());
  for (Eigen::Index j = 0; j < V.cols(); ++j) out.col(j) = apply(V.col(j));
  return out;
}

Eigen::VectorXd BoxDiscQP::diagonal() const {
  const Eigen::VectorXd d = Q ? Eigen::VectorXd((*Q).diagonal()) : q_diagonal;
  Eigen::VectorXd scaled = scale.size() ? Eigen::VectorXd(d.cwiseProduct(scale.cwiseAbs2())) : d;
  if (has_low_rank()) scaled += low_rank.colwise().squaredNorm().transpose();
  return scaled;
}

Eigen::VectorXd BoxDiscQP::apply_single(const Eigen::VectorXd& v) const {
  if (Q_single) return with_low_rank(symmetric_product(Q_single, single_scale, v), low_rank, v);
  if (!single_product) return apply(v);
  if (scale.size() == 0) return with_low_rank(single_product(v), low_rank, v);
  return with_low_rank(Eigen::VectorXd(scale.cwiseProduct(single_product(scale.cwiseProduct(v)))), low_rank, v);
}

Eigen::MatrixXd BoxDiscQP::apply_block_single(const Eigen::MatrixXd& V) const {
  if (Q || !single_block_product) return apply_block(V);
  if (scale.size() == 0) return with_low_rank(single_block_product(V), low_rank, V);
  return with_low_rank(Eigen::MatrixXd(scale.asDiagonal() * single_block_product(scale.asDiagonal() * V)), low_rank, V);
}

double BoxDiscQP::value(const Eigen::VectorXd& lambda) const { return 0.5 * lambda.dot(apply(lambda)) - h.dot(lambda); }

bool prepare_start(const BoxDiscQP& qp, Eigen::VectorXd& lambda) {
  if (lambda.size() != qp.size()) lambda = Eigen::VectorXd::Zero(qp.size());
  if (qp.h.norm() == 0) {
    lambda.setZero();
    return false;
  }
  project(qp, lambda);
  return true;
}

void project(const BoxDiscQP& qp, Eigen::VectorXd& lambda) {
  const int r = qp.r;
  for (int i = 0; i < r; ++i) lambda[i] = std::max(lambda[i], 0.0);
  if (!qp.with_friction) return;
  for (int i = 0; i < r; ++i) {
    const double c = qp.radius[i];
    const int a = qp.layout().t1(i), b = qp.layout().t2(i);
    const double norm = std::hypot(lambda[a], lambda[b]);
    if (norm > c) {
      const double s = norm > 0 ? c / norm : 0.0;
      lambda[a] *= s;
      lambda[b] *= s;
    }
  }
}

bool is_feasible(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, double rel_tol) {
  const int r = qp.r;
  for (int i = 0; i < r; ++i)
    if (lambda[i] < 0) return false;
  if (!qp.with_friction) return true;
  for (int i = 0; i < r; ++i)
    if (std::hypot(lambda[qp.layout().t1(i)], lambda[qp.layout().t2(i)]) > qp.radius[i] * (1 + rel_tol)) return false;
  return true;
}

GradientSplit split_gradient(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, const Eigen::VectorXd& g) {
  const int r = qp.r;
  GradientSplit s{Eigen::VectorXd::Zero(g.size()), Eigen::VectorXd::Zero(g.size())};
  for (int i = 0; i < r; ++i) {
    if (lambda[i] > 0)
      s.free[i] = g[i];
    else
      s.chopped[i] = std::min(g[i], 0.0);
  }
  if (!qp.with_friction) return s;
  for (int i = 0; i < r; ++i) {
    const int a = qp.layout().t1(i), b = qp.layout().t2(i);
    const double c = qp.radius[i];
    if (c <= 0) continue;  // the disc is a point: nothing can move
    const double norm = std::hypot(lambda[a], lambda[b]);
    if (norm < c * (1 - kActiveRelTol)) {
      s.free[a] = g[a];
      s.free[b] = g[b];
      continue;
    }
    const double nu_a = lambda[a] / norm, nu_b = lambda[b] / norm;
    const double outward = nu_a * g[a] + nu_b * g[b];  // −g points inward when this is > 0
    if (outward > 0) {
      s.chopped[a] = g[a];
      s.chopped[b] = g[b];
    } else {
      s.chopped[a] = g[a] - outward * nu_a;
      s.chopped[b] = g[b] - outward * nu_b;
    }
  }
  return s;
}

double max_feasible_step(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, const Eigen::VectorXd& p) {
  const int r = qp.r;
  double step = std::numeric_limits<double>::infinity();
  for (int i = 0; i < r; ++i)
    if (p[i] > 0) step = std::min(step, lambda[i] / p[i]);
  if (!qp.with_friction) return step;
  for (int i = 0; i < r; ++i) {
    const int a = qp.layout().t1(i), b = qp.layout().t2(i);
    step = std::min(step, max_step_in_disc(lambda[a], lambda[b], p[a], p[b], qp.radius[i]));
  }
  return std::max(step, 0.0);
}

double max_step_in_disc(double la, double lb, double pa, double pb, double c) {
  const double pp = pa * pa + pb * pb;
  if (pp == 0) return std::numeric_limits<double>::infinity();
  const double lp = la * pa + lb * pb;
  const double slack = std::max(0.0, c * c - (la * la + lb * lb));
  // ‖λ − a p‖ = c  <=>  pp a² − 2 lp a − slack = 0; the positive root, written stably.
  const double disc = std::sqrt(lp * lp + pp * slack);
  return lp >= 0 ? (lp + disc) / pp : slack / (disc - lp);
}

double reduced_gradient_norm(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, const Eigen::VectorXd& g,
                             double alpha) {
  Eigen::VectorXd y = lambda - alpha * g;
  project(qp, y);
  return (lambda - y).norm() / alpha;
}

}  // namespace contact3d
