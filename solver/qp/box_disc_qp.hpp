// The dual quadratic program (5.5): minimise S(λ) = ½ λᵀQλ − hᵀλ over
//   λ_n,i >= 0 (5.2) and ‖(λ_t1,i, λ_t2,i)‖ <= c_i (5.3),   i = 1..r,
// with λ laid out as [λ_n (r) | λ_t1 (r) | λ_t2 (r)] (normal block only when frictionless).
// This header holds the problem and the geometry of its feasible set (projection, free and
// chopped gradients, longest feasible step); solvers know nothing else about contact.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "base/multiplier_layout.hpp"
#include "linalg/dense_view.hpp"
#include "linalg/symmetric_product.hpp"

namespace contact3d {

class BorderedNewton;
struct CoarseProducts;
struct LumpedOperators;

struct BoxDiscQP {
  DenseViewPtr Q;  // Q (a view: held by the dual problem, or where the factorization left it)
  // Matrix-free (Q null): Q v by `product` (through the factor of K, linalg/dual_problem.hpp)
  // and Q's diagonal given. MPGP works on it as on Q; Newton steps solve their reduced systems by CG
  // (reduced_cg.hpp), having no entries to factor.
  std::function<Eigen::VectorXd(const Eigen::VectorXd&)> product;
  Eigen::VectorXd q_diagonal;
  // Matrix-free, optional: Q V for several columns at once (one blocked solve through the factor,
  // far cheaper per column than single products), and the coarse group of each multiplier (cells
  // aggregated by position on Γc, each component apart) whose indicator vectors the Newton steps' CG
  // deflates (reduced_cg.hpp). Either empty: CG with the diagonal alone.
  std::function<Eigen::MatrixXd(const Eigen::MatrixXd&)> block_product;
  std::vector<int> coarse_group;
  std::shared_ptr<CoarseProducts> coarse_products;  // the coarse space's products kept between Newton steps
  // Matrix-free, optional: 𝔹𝔹ᵀ and 𝔹K𝔹ᵀ, from which the Newton steps' CG is preconditioned in place of
  // the diagonal (lumped_preconditioner.hpp).
  std::shared_ptr<const LumpedOperators> lumped;
  // Optional diagonal scaling: the problem's operator is then S Q S, S = diag(scale) (the Jacobi
  // scaling, jacobi_scaling.hpp), applied in each product instead of stored as a second dense copy
  // (m² doubles: 800 MB at 10 000 multipliers). Empty: Q itself. Read Q through apply(),
  // entry_factor() and diagonal(), never directly.
  Eigen::VectorXd scale;
  // Optional single-precision copy of Q (its lower triangle is read): products through it stream
  // half the bytes (BLAS ssymv, 1.8-2.7x faster than dsymv at 4800-14000 multipliers). MPGP uses it
  // for recursive updates of the gradient and checks convergence with apply() (mpgp.hpp); when it is
  // set, Newton steps factor their reduced systems in single precision and refine in double (ssn.hpp).
  SingleSymmetric Q_single;  // (linalg/symmetric_product.hpp) null: none
  double single_scale = 1;   // Q = single_scale · Q_single (kept near 1 in float: no under- or overflow)
  // Matrix-free, optional: Q v through a single-precision copy of K's factor (half the bytes of a
  // product by `product`; linalg/single_precision_factor.hpp), used as Q_single is by MPGP.
  std::function<Eigen::VectorXd(const Eigen::VectorXd&)> single_product;
  std::function<Eigen::MatrixXd(const Eigen::MatrixXd&)> single_block_product;  // the same for several columns
  // Optional solver of the Newton steps' reduced systems through a factor of the whole Q, kept for
  // the scene (bordered_newton.hpp); Newton steps try it before factoring the reduced matrix.
  BorderedNewton* bordered = nullptr;
  // Optional low-rank term: the operator becomes (S) Q (S) + AᵀA, A = low_rank (k × m, k <= 6, in the
  // problem's own variables). The augmented Lagrangian's penalty (dual_qp_solver.cpp): every product,
  // the diagonal and the Newton steps' reduced systems take it in, so its inner problems keep Q's
  // single copy and the bordered factor (ssn.cpp adds AᵀA to the latter by a Woodbury update).
  Eigen::MatrixXd low_rank;
  Eigen::VectorXd h;
  int r = 0;
  bool with_friction = true;
  Eigen::VectorXd radius;  // c_i (size r; ignored when frictionless)
  double q_norm = 0;       // ‖Q‖, or an estimate of it with a small safety margin (see estimate_norm)

  MultiplierLayout layout() const { return {r, with_friction}; }
  bool has_low_rank() const { return low_rank.rows() > 0; }
  bool matrix_free() const { return Q == nullptr; }
  int size() const { return layout().size(); }
  // Q v from the lower triangle only (linalg/symmetric_product.hpp), scaled when `scale` is set.
  Eigen::VectorXd apply(const Eigen::VectorXd& v) const;
  // Q V for several columns at once (dsymm on a dense Q, block_product matrix-free; column by column
  // where there is neither); scaled as apply().
  Eigen::MatrixXd apply_block(const Eigen::MatrixXd& V) const;
  // The operator's diagonal, and the factor its entry (i, j) carries over Q's (1 without a scale).
  Eigen::VectorXd diagonal() const;
  double entry_factor(Eigen::Index i) const { return scale.size() ? scale[i] : 1.0; }
  // Q v through Q_single (rounding error about 1e-7 ‖Q‖‖v‖) or single_product (scaled as apply());
  // apply() when there is neither.
  Eigen::VectorXd apply_single(const Eigen::VectorXd& v) const;
  // Q V through single_block_product (scaled as apply_block()); apply_block() when there is none.
  Eigen::MatrixXd apply_block_single(const Eigen::MatrixXd& V) const;
  bool has_single_products() const { return static_cast<bool>(Q_single) || static_cast<bool>(single_product); }
  double value(const Eigen::VectorXd& lambda) const;
};

// Euclidean projection onto the feasible set.
void project(const BoxDiscQP& qp, Eigen::VectorXd& lambda);
// Every solver's start: λ made feasible (zero when its size does not match). Returns false when
// h = 0, where the minimiser of ½λᵀQλ is λ = 0 and λ is set to it (nothing left to solve).
bool prepare_start(const BoxDiscQP& qp, Eigen::VectorXd& lambda);
bool is_feasible(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, double rel_tol = 1e-12);

// Free gradient φ (gradient on free components, 0 on active ones) and chopped gradient β
// (the part of the projected gradient on active components); gᴾ = φ + β.
struct GradientSplit {
  Eigen::VectorXd free, chopped;
};
GradientSplit split_gradient(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, const Eigen::VectorXd& g);

// Largest a >= 0 with λ − a p feasible (λ feasible).
double max_feasible_step(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, const Eigen::VectorXd& p);
// The same for one disc: largest a >= 0 with ‖(la, lb) − a (pa, pb)‖ <= c, (la, lb) inside it (∞ for p = 0).
double max_step_in_disc(double la, double lb, double pa, double pb, double c);

// ‖(λ − P(λ − α g)) / α‖: the reduced projected gradient (continuous in λ).
double reduced_gradient_norm(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, const Eigen::VectorXd& g,
                             double alpha);

}  // namespace contact3d
