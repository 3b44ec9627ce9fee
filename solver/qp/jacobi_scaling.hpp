// Diagonal (Jacobi) scaling of the dual QP (5.5) that keeps the shape of its constraints:
// λ = S μ with one factor s_n,i per normal multiplier and one factor s_t,i shared by the two
// tangential multipliers of cell i (s = 1/√Q_jj, the larger tangential diagonal for the pair), so
// half-lines stay half-lines and discs stay discs of radius c_i / s_t,i. The scaled problem
// has Ŝ(μ) = S(Sμ); MPGP on it converges far faster when cells differ in size or shape (the
// paper's MPGP is the unscaled one: solver.qp_scaling = "none").
#pragma once

#include <Eigen/Core>

#include "qp/box_disc_qp.hpp"

namespace contact3d {

class JacobiScaledQP {
 public:
  // The scaled problem's ‖Q̂‖ by Lanczos steps (estimate_norm) in double, or left for the caller to set (set_norm)
  // when it estimates it from a single-precision copy.
  explicit JacobiScaledQP(const BoxDiscQP& qp, bool estimate_norm = true);
  void set_norm(double q_norm) { qp_.q_norm = q_norm; }
  // A new linear term h of the original problem (the scaled one gets S h).
  void set_linear_term(const Eigen::VectorXd& h) { qp_.h = qp_.scale.cwiseProduct(h); }
  // The scaled problem for the current radii of the original one.
  const BoxDiscQP& scaled(const Eigen::VectorXd& radius);
  Eigen::VectorXd to_scaled(const Eigen::VectorXd& lambda) const { return lambda.cwiseQuotient(scale()); }
  Eigen::VectorXd from_scaled(const Eigen::VectorXd& mu) const { return mu.cwiseProduct(scale()); }
  const Eigen::VectorXd& scale() const { return qp_.scale; }  // S

 private:
  BoxDiscQP qp_;  // the original Q with scale = S
};

}  // namespace contact3d
