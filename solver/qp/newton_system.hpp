// The reduced Newton system of the dual QP (5.5) at given active sets — shared by the semismooth
// Newton solver (ssn.hpp) and the sensitivity of the solution to the disc radii
// (radius_sensitivity.hpp). For z = λ − ρ g(λ), the generalized Jacobian of
//   F(λ) = λ − P(λ − ρ (Qλ − h)),   P the projection onto {λ_n >= 0, ‖λ_t,i‖ <= c_i},
// fixes part of λ (λ_n = 0 off contact, λ_t = 0 on a point disc, λ_t = c ν on a sliding disc,
// ν = z_t / ‖z_t‖) and leaves free unit directions d_k (normal in contact, tangential inside a disc)
// and the sliding tangents τ ⊥ ν, each with the diagonal term (1 − κ) / (ρ κ), κ = c / ‖z_t‖:
//   λ = λ_fixed + Σ_k y_k d_k,   (Dᵀ Q D + diag(shift)) y = Dᵀ (h − Q λ_fixed).
// This is J δ = −F row by row in the (ν, τ) frame of each sliding disc, and, unlike J, it is
// symmetric positive definite.
#pragma once

#include <stdexcept>
#include <vector>

#include <Eigen/Core>

#include "qp/box_disc_qp.hpp"

namespace contact3d {

// One unknown of the reduced system: λ moves along w_a e_a + w_b e_b (b < 0: a unit vector), and
// `shift` is the diagonal term a sliding disc adds in its tangent direction.
struct Direction {
  int a, b;
  double w_a, w_b, shift;
};

struct ReducedStep {
  Eigen::VectorXd lambda_fixed;  // what the active sets fix (c ν on sliding discs, 0 elsewhere)
  std::vector<Direction> directions;
};

// ρ of z = λ − ρ g: 1 / (mean diagonal of Q), which scales the gradient to the size of λ.
double projection_scale(const BoxDiscQP& qp);

// The active sets of z = λ − ρ g and the reduced system's unknowns.
ReducedStep split_active_sets(const BoxDiscQP& qp, const Eigen::VectorXd& z, double rho);

// Where the minimiser `target` of a step's reduced system leaves the feasible set early along
// δ = target − λ (λ feasible): a free normal multiplier that crosses zero, or a disc free inside
// that crosses its circle, at a fraction a_i < `early` of δ. Those unknowns leave the step's
// directions and are fixed at the bound they cross (λ_n = 0; λ_t at the point where δ meets the
// circle), so that the reduced system solved again has its minimiser further in. A thin body's soft
// bending modes make such exits common near the solution: the cells that barely touch are pushed far
// below zero by a face minimiser that moves λ along those modes. `first_exit` is the smallest a_i of
// the exits kept (1 when there are none): λ + a δ stays feasible up to it, but for the sliding
// discs' tangent lines.
struct EarlyExits {
  int fixed = 0;
  double first_exit = 1;
};
EarlyExits fix_early_exits(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, const Eigen::VectorXd& target,
                           double early, ReducedStep& step);

// A D (k_A × k) for the problem's low-rank term A (BoxDiscQP::low_rank): the reduced system's
// operator is Dᵀ Q D + diag(shift) + (A D)ᵀ(A D).
Eigen::MatrixXd reduced_low_rank(const BoxDiscQP& qp, const std::vector<Direction>& d);

// Dᵀ Q D + diag(shift) (+ the low-rank term's share), lower triangle (column-major, k x k), in double or in single
// precision, for the problem's operator (qp.scale taken into the directions' weights).
template <typename Matrix>
void reduced_matrix(const BoxDiscQP& qp, const std::vector<Direction>& d, Matrix& A) {
  using Scalar = typename Matrix::Scalar;
  if (qp.matrix_free()) throw std::logic_error("a Newton system needs Q's entries, which a matrix-free dual has not");
  const DenseView& Q = *qp.Q;
  std::vector<Direction> w = d;  // weights on Q's own entries
  for (Direction& e : w) {
    e.w_a *= qp.entry_factor(e.a);
    if (e.b >= 0) e.w_b *= qp.entry_factor(e.b);
  }
  const int k = static_cast<int>(w.size());
  A.resize(k, k);
  for (int col = 0; col < k; ++col) {
    const Direction& c = w[static_cast<std::size_t>(col)];
    const double* qa = Q.col(c.a).data();
    const double* qb = c.b >= 0 ? Q.col(c.b).data() : nullptr;
    for (int row = col; row < k; ++row) {
      const Direction& e = w[static_cast<std::size_t>(row)];
      double v = c.w_a * (e.w_a * qa[e.a] + (e.b >= 0 ? e.w_b * qa[e.b] : 0.0));
      if (qb) v += c.w_b * (e.w_a * qb[e.a] + (e.b >= 0 ? e.w_b * qb[e.b] : 0.0));
      A(row, col) = static_cast<Scalar>(row == col ? v + c.shift : v);
    }
  }
  if (!qp.has_low_rank()) return;
  const Eigen::MatrixXd C = reduced_low_rank(qp, d);  // (A D)ᵀ(A D), the low-rank term's share
  A.template triangularView<Eigen::Lower>() += (C.transpose() * C).template cast<Scalar>();
}

// (Dᵀ Q D + diag(shift)) y with one product by Q in double, or through BoxDiscQP::apply_single
// where `single` is set.
Eigen::VectorXd reduced_product(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::VectorXd& y,
                                bool single = false);
// The same for the columns of Y at once (BoxDiscQP::apply_block).
Eigen::MatrixXd reduced_block_product(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::MatrixXd& Y);
// The products of the reduced operator A = Dᵀ Q D + diag(shift) in an iterative refinement in
// double: through Q (reduced_product) until keep(), then, where the directions are few beside m
// (k <= m / 2), through A's entries gathered once and kept in double — a product then reads k² / 2
// entries instead of Q's m² / 2. The sensitivity's blocked reduced solves keep them
// (radius_sensitivity.hpp: the joint Newton steps of a free plate, k = 300 … 1 800 of m = 4 800,
// refine k + 1 columns at once, and a product through Q was most of a step's time). The QP's own
// Newton steps do not: on the clamped slab with 10 092 multipliers that cost 112 MiB of peak memory
// and no time, and on the free plate it gained nothing measurable. It holds no reference: every call
// takes the problem and the directions it is for (so that its holder may be moved).
class ReducedOperator {
 public:
  void keep(const BoxDiscQP& qp, const std::vector<Direction>& d);
  bool kept() const { return A_.size() > 0; }
  Eigen::VectorXd product(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::VectorXd& y) const;
  Eigen::MatrixXd block_product(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::MatrixXd& Y) const;

 private:
  Eigen::MatrixXd A_;  // lower triangle (the upper one 0), once kept
};

// Dᵀ v (the reduced right-hand side of a full-size v) and D y (a reduced vector in full size).
Eigen::VectorXd restrict_to(const std::vector<Direction>& d, const Eigen::VectorXd& v);
Eigen::MatrixXd restrict_columns(const std::vector<Direction>& d, const Eigen::MatrixXd& V);  // Dᵀ V
Eigen::VectorXd prolong(const std::vector<Direction>& d, const Eigen::VectorXd& y, int size);
Eigen::MatrixXd prolong(const std::vector<Direction>& d, const Eigen::MatrixXd& Y, int size);

}  // namespace contact3d
