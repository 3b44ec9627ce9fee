// The reduced Newton system of the dual QP (newton_system.hpp),
//   (Dᵀ Q D + diag(shift)) y = b,
// solved through one Cholesky factor Q = L Lᵀ of the whole Q (the stability check's, kept) instead
// of a new factorization of the free size k at every step. With D and the fixed directions N
// completing each other (an orthonormal basis), x = D y is the minimiser of
// ½ xᵀ(Q + T S Tᵀ)x − (D b)ᵀx subject to Nᵀx = 0 (T: the directions with a shift S, the sliding
// tangents). Bordering Q with U = [N T]:
//   Q x + U v = D b,   Uᵀ x − C v = 0,   C = diag(0 on N, S⁻¹ on T),
// so (Uᵀ Q⁻¹ U + C) v = Uᵀ Q⁻¹ D b, x = Q⁻¹(D b − U v), y = Dᵀ x — a system of the size p of the
// border (cells off contact, point discs, sliding discs) instead of k. Every border vector combines
// at most two unit vectors e_i, and W_i = L⁻¹ e_i and the Gram matrix Wᵢᵀ W_j = (Q⁻¹)_ij are
// cached for the whole run (Q does not change between solves, only the radii): a step pays for
// the unit vectors that are new to the border (m² each), its p × p Cholesky and two triangular
// solves per right-hand side. prepare() takes this route only when it costs fewer flops than
// factoring the reduced matrix (k³/3) plus the reduced factorizations it refused since its last
// fill (ski rental: the cache, once bought, serves the later steps): on a slab most cells touch and
// few change from one step to the next, on a brick with a small contact zone k is small and the
// reduced matrix wins.
// In single precision (a single factor of Q) the answer is approximate; the caller refines it in
// double (ssn.cpp) and reports the products each refinement took (record_refinement). Where cond(Q)
// · ε_single nears 1 (the free thin slab: 1.5e7 · 6e-8) a refinement step hardly contracts (10–16
// products a solve instead of 2–4); given Q, the solver then factors Q once in double and goes on
// with that factor (its solves still refined, in one or two products) once the products spent beyond
// a good refinement's have cost as much as that factorization and its cache would (ski rental, as in
// prepare()).
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "linalg/dense_cholesky.hpp"
#include "linalg/dense_view.hpp"
#include "qp/newton_system.hpp"

namespace contact3d {

class BorderedNewton {
 public:
  virtual ~BorderedNewton() = default;
  // Sets up the system of the directions `d` (of an m-sized λ) when the bordered route is cheaper
  // than factoring Dᵀ Q D + diag(shift); false otherwise (or when its small factorization fails),
  // and solve() must not be called.
  virtual bool prepare(const std::vector<Direction>& d) = 0;
  // y = (Dᵀ Q D + diag(shift))⁻¹ b for the directions of the last successful prepare().
  virtual Eigen::VectorXd solve(const Eigen::VectorXd& b) const = 0;
  // The same for the columns of B at once: the factor and the cache read once for all of them
  // (triangular solves and products by blocks), where solve() per column reads them per column.
  virtual Eigen::MatrixXd solve_columns(const Eigen::MatrixXd& B) const = 0;
  // Flops of the last successful prepare() (the unit vectors it added, the border's factorization).
  virtual double prepare_flops() const = 0;
  // Whether solve() is accurate to double's rounding (a factor in double) and needs no refinement.
  virtual bool exact() const = 0;
  // Unit vectors whose L⁻¹ e_i is cached (the tests check the cache with it).
  virtual int cached_units() const = 0;
  // Calls of prepare() so far, successful or not: a holder of a prepared system (the QP's Newton
  // step, RadiusSensitivity) whose count has moved on must prepare it again before solve().
  virtual long preparations() const = 0;
  // The products by Q that refining one solve in double took (the caller's iterative refinement and
  // CG). Only a solver that can switch to a factor in double acts on it.
  virtual void record_refinement(int /*products*/) {}
  // Whether the solver has switched from its single factor to one of Q in double.
  virtual bool switched_to_double() const { return false; }
};

// For the QP on S Q S (S = diag(scale): the Jacobi scaling, jacobi_scaling.hpp; ones for the plain
// problem) from a factor of Q. The factor is shared: it lives as long as the solver that uses it.
// With `Q` (the matrix the factor is of, which must outlive the solver) a single factor may be
// replaced by one of Q in double when its refinements stall (see the top of this file).
std::unique_ptr<BorderedNewton> make_bordered_newton(std::shared_ptr<const DualOperatorFactor> factor,
                                                     const Eigen::VectorXd& scale, DenseViewPtr Q = nullptr);

}  // namespace contact3d
