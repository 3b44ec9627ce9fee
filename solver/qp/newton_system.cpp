#include "qp/newton_system.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace contact3d {

double projection_scale(const BoxDiscQP& qp) { return qp.size() / std::max(qp.diagonal().sum(), 1e-300); }

ReducedStep split_active_sets(const BoxDiscQP& qp, const Eigen::VectorXd& z, double rho) {
  const int r = qp.r;
  ReducedStep step{Eigen::VectorXd::Zero(z.size()), {}};
  step.directions.reserve(static_cast<std::size_t>(z.size()));
  for (int i = 0; i < r; ++i)
    if (z[i] > 0) step.directions.push_back({i, -1, 1.0, 0.0, 0.0});
  if (!qp.with_friction) return step;
  for (int i = 0; i < r; ++i) {
    const int a = qp.layout().t1(i), b = qp.layout().t2(i);
    const double c = qp.radius[i], zn = std::hypot(z[a], z[b]);
    if (c <= 0) continue;  // a point disc: λ_t = 0
    if (zn <= c) {         // inside the disc
      step.directions.push_back({a, -1, 1.0, 0.0, 0.0});
      step.directions.push_back({b, -1, 1.0, 0.0, 0.0});
      continue;
    }
    const double nu_a = z[a] / zn, nu_b = z[b] / zn, kappa = c / zn;
    step.lambda_fixed[a] = c * nu_a;
    step.lambda_fixed[b] = c * nu_b;
    step.directions.push_back({a, b, -nu_b, nu_a, (1 - kappa) / (rho * kappa)});
  }
  return step;
}

EarlyExits fix_early_exits(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, const Eigen::VectorXd& target,
                           double early, ReducedStep& step) {
  const MultiplierLayout layout = qp.layout();
  const Eigen::VectorXd delta = target - lambda;
  EarlyExits exits;
  std::vector<char> disc_fixed(static_cast<std::size_t>(qp.r), 0);
  if (qp.with_friction)
    for (const Direction& d : step.directions) {
      if (d.b >= 0 || d.a < 2 * qp.r) continue;  // a disc free inside has two unit directions; t2 stands for it
      const int i = d.a - 2 * qp.r, a = layout.t1(i), b = layout.t2(i);
      const double c = qp.radius[i];
      if (std::hypot(target[a], target[b]) <= c) continue;
      const double exit = max_step_in_disc(lambda[a], lambda[b], -delta[a], -delta[b], c);  // λ_t + exit δ_t on it
      if (exit >= early) {
        exits.first_exit = std::min(exits.first_exit, exit);
        continue;
      }
      double xa = lambda[a] + exit * delta[a], xb = lambda[b] + exit * delta[b];
      const double norm = std::hypot(xa, xb);
      if (norm > 0) xa *= c / norm, xb *= c / norm;  // on the circle exactly
      step.lambda_fixed[a] = xa;
      step.lambda_fixed[b] = xb;
      disc_fixed[static_cast<std::size_t>(i)] = 1;
      ++exits.fixed;
    }
  std::vector<Direction> kept;
  kept.reserve(step.directions.size());
  for (const Direction& d : step.directions) {
    const bool unit = d.b < 0;
    if (unit && d.a >= qp.r && disc_fixed[static_cast<std::size_t>((d.a - qp.r) % qp.r)]) continue;
    if (unit && d.a < qp.r && target[d.a] < 0) {
      const double exit = lambda[d.a] / -delta[d.a];
      if (exit < early) {
        step.lambda_fixed[d.a] = 0;
        ++exits.fixed;
        continue;
      }
      exits.first_exit = std::min(exits.first_exit, exit);
    }
    kept.push_back(d);
  }
  step.directions = std::move(kept);
  return exits;
}

Eigen::MatrixXd reduced_low_rank(const BoxDiscQP& qp, const std::vector<Direction>& d) {
  Eigen::MatrixXd C(qp.low_rank.rows(), static_cast<Eigen::Index>(d.size()));
  for (std::size_t j = 0; j < d.size(); ++j) {
    const Eigen::Index col = static_cast<Eigen::Index>(j);
    C.col(col) = d[j].w_a * qp.low_rank.col(d[j].a);
    if (d[j].b >= 0) C.col(col) += d[j].w_b * qp.low_rank.col(d[j].b);
  }
  return C;
}

Eigen::VectorXd reduced_product(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::VectorXd& y,
                                bool single) {
  const Eigen::VectorXd v = prolong(d, y, qp.size());
  Eigen::VectorXd out = restrict_to(d, single ? qp.apply_single(v) : qp.apply(v));
  for (std::size_t j = 0; j < d.size(); ++j)
    out[static_cast<Eigen::Index>(j)] += d[j].shift * y[static_cast<Eigen::Index>(j)];
  return out;
}

Eigen::MatrixXd prolong(const std::vector<Direction>& d, const Eigen::MatrixXd& Y, int size) {
  Eigen::MatrixXd V = Eigen::MatrixXd::Zero(size, Y.cols());
  for (std::size_t j = 0; j < d.size(); ++j) {
    const Eigen::Index row = static_cast<Eigen::Index>(j);
    V.row(d[j].a) += d[j].w_a * Y.row(row);
    if (d[j].b >= 0) V.row(d[j].b) += d[j].w_b * Y.row(row);
  }
  return V;
}

Eigen::MatrixXd reduced_block_product(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::MatrixXd& Y) {
  const Eigen::Index k = static_cast<Eigen::Index>(d.size());
  Eigen::MatrixXd out = restrict_columns(d, qp.apply_block(prolong(d, Y, qp.size())));
  for (Eigen::Index j = 0; j < k; ++j) out.row(j) += d[static_cast<std::size_t>(j)].shift * Y.row(j);
  return out;
}

void ReducedOperator::keep(const BoxDiscQP& qp, const std::vector<Direction>& d) {
  const auto k = static_cast<Eigen::Index>(d.size());
  if (kept() || !qp.Q || k == 0 || 2 * k > qp.size()) return;
  A_.setZero(k, k);
  reduced_matrix(qp, d, A_);
}

Eigen::VectorXd ReducedOperator::product(const BoxDiscQP& qp, const std::vector<Direction>& d,
                                         const Eigen::VectorXd& y) const {
  if (!kept()) return reduced_product(qp, d, y);
  return A_.selfadjointView<Eigen::Lower>() * y;
}

Eigen::MatrixXd ReducedOperator::block_product(const BoxDiscQP& qp, const std::vector<Direction>& d,
                                               const Eigen::MatrixXd& Y) const {
  if (!kept()) return reduced_block_product(qp, d, Y);
  return A_.selfadjointView<Eigen::Lower>() * Y;
}

Eigen::VectorXd restrict_to(const std::vector<Direction>& d, const Eigen::VectorXd& v) {
  Eigen::VectorXd y(static_cast<Eigen::Index>(d.size()));
  for (std::size_t j = 0; j < d.size(); ++j)
    y[static_cast<Eigen::Index>(j)] = d[j].w_a * v[d[j].a] + (d[j].b >= 0 ? d[j].w_b * v[d[j].b] : 0.0);
  return y;
}

Eigen::MatrixXd restrict_columns(const std::vector<Direction>& d, const Eigen::MatrixXd& V) {
  Eigen::MatrixXd Y(static_cast<Eigen::Index>(d.size()), V.cols());
  for (std::size_t j = 0; j < d.size(); ++j) {
    const Eigen::Index row = static_cast<Eigen::Index>(j);
    Y.row(row) = d[j].w_a * V.row(d[j].a);
    if (d[j].b >= 0) Y.row(row) += d[j].w_b * V.row(d[j].b);
  }
  return Y;
}

Eigen::VectorXd prolong(const std::vector<Direction>& d, const Eigen::VectorXd& y, int size) {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(size);
  for (std::size_t j = 0; j < d.size(); ++j) {
    v[d[j].a] += d[j].w_a * y[static_cast<Eigen::Index>(j)];
    if (d[j].b >= 0) v[d[j].b] += d[j].w_b * y[static_cast<Eigen::Index>(j)];
  }
  return v;
}

}  // namespace contact3d
