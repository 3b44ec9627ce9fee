// Residuals of the discrete optimality conditions (5.4) of a computed (w, λ), each scaled to
// be dimensionless, so that a run reports how well it solved its own problem. With d = 𝔹w + b
// (b the rows' offset: prescribed displacements on Γc and the initial gap, see ContactOperator),
// s_d = max(‖d‖, ‖h‖) (h = 𝔹K⁻¹f + b, the unconstrained d: never ~0 when the body is loaded, unlike
// ‖d‖ in a fully stuck contact) and s_λ = max(‖λ‖, ‖c‖):
//   equilibrium             ‖K w − f + 𝔹ᵀλ‖ / max(‖f‖, ‖𝔹ᵀλ‖)   (K w given, as Kw)
//   normal_feasibility      ‖max(0, d_n)‖ / s_d                     (∫_{R_i} w_n <= 0)
//   normal_complementarity  |Σ λ_n,i d_n,i| / (s_λ s_d)
//   disc_feasibility        max_i max(0, ‖λ_t,i‖ − c_i) / max_i c_i
//   slip_alignment          Σ (c_i ‖d_t,i‖ − λ_t,iᵀ d_t,i) / (s_λ s_d)   (λ_t maximises μᵀd on the discs)
// The sums above can hide one bad cell among many good ones; the cell by cell natural residuals
// (the projection form of (5.4), zero exactly where cell i meets its conditions) cannot. With
// ρ = S_λ / S_d from the largest entries (S_λ = max(‖λ‖∞, ‖c‖∞), S_d = max(‖d‖∞, ‖h‖∞)):
//   normal_cellwise         max_i |λ_n,i − max(0, λ_n,i + ρ d_n,i)| / S_λ
//   friction_cellwise       max_i ‖λ_t,i − P_{c_i}(λ_t,i + ρ d_t,i)‖ / S_λ   (P_c: onto the disc of radius c)
// worst_cell names the cell of the larger of the two (−1 without contact).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace contact3d {

struct KktResiduals {
  double equilibrium = 0, normal_feasibility = 0, normal_complementarity = 0;
  double disc_feasibility = 0, slip_alignment = 0;
  double normal_cellwise = 0, friction_cellwise = 0;
  int worst_cell = -1;
  double max() const;
};

KktResiduals kkt_residuals(const Eigen::VectorXd& Kw, const Eigen::VectorXd& f, const Eigen::SparseMatrix<double>& B,
                           int r, bool with_friction, const Eigen::VectorXd& radius, const Eigen::VectorXd& w,
                           const Eigen::VectorXd& lambda, const Eigen::VectorXd& h,
                           const Eigen::VectorXd& offset = Eigen::VectorXd());

}  // namespace contact3d
