#include "qp/radius_sensitivity.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "qp/bordered_newton.hpp"
#include "qp/reduced_cg.hpp"

namespace contact3d {

RadiusSensitivity::RadiusSensitivity(const BoxDiscQP& qp, const Eigen::VectorXd& solution, bool single_precision,
                                     const Eigen::VectorXd& scale, const Eigen::MatrixXd& equality)
    : qp_(qp), scale_(scale), single_precision_(single_precision), nu_(Eigen::VectorXd::Zero(qp.size())) {
  if (equality.rows()) {
    G_ = scale_.size() ? Eigen::MatrixXd(equality * scale_.asDiagonal()) : equality;
    dmu_ = Eigen::VectorXd::Zero(equality.rows());
  }
  // The active sets of z = λ − ρ g, with the semismooth Newton solver's ρ.
  const double rho = projection_scale(qp_);
  const Eigen::VectorXd z = solution - rho * (qp_.apply(solution) - qp_.h);
  if (qp_.matrix_free()) ++products_;
  step_ = split_active_sets(qp_, z, rho);
  if (qp_.with_friction)
    for (int i = 0; i < qp_.r; ++i) {
      const int a = qp_.layout().t1(i), b = qp_.layout().t2(i);
      const double c = qp_.radius[i];
      if (c > 0 && (step_.lambda_fixed[a] != 0 || step_.lambda_fixed[b] != 0)) {
        nu_[a] = step_.lambda_fixed[a] / c;
        nu_[b] = step_.lambda_fixed[b] / c;
      }
    }
  if (step_.directions.empty() || qp_.matrix_free()) {  // nothing to solve, or by CG in each apply()
    ok_ = true;
    return;
  }
  if (qp_.bordered && qp_.bordered->prepare(step_.directions)) {
    bordered_preparation_ = qp_.bordered->preparations();
    ok_ = true;
    return;
  }
  ok_ = factor_reduced_matrix();
}

bool RadiusSensitivity::factor_reduced_matrix() {
  if (single_precision_) {
    Eigen::MatrixXf A;
    reduced_matrix(qp_, step_.directions, A);
    single_factor_.emplace(std::move(A));
    return single_factor_->ok();
  }
  Eigen::MatrixXd A;
  reduced_matrix(qp_, step_.directions, A);
  factor_.emplace(std::move(A));
  return factor_->ok();
}

// Whether our system is still the one the bordered solver holds; a QP solve in between (the
// derivative is asked for after the next evaluation) re-prepares it, and a failure there falls back
// to factoring the reduced matrix.
bool RadiusSensitivity::bordered_ready() {
  if (bordered_preparation_ < 0) return false;
  if (qp_.bordered->preparations() == bordered_preparation_) return true;
  if (qp_.bordered->prepare(step_.directions)) {
    bordered_preparation_ = qp_.bordered->preparations();
    return true;
  }
  bordered_preparation_ = -1;
  ok_ = factor_reduced_matrix();
  return false;
}

// One solve and one step of refinement in double (one product by Q); by CG on a matrix-free Q.
bool RadiusSensitivity::solve_reduced(const Eigen::VectorXd& b, Eigen::VectorXd& y) {
  if (qp_.matrix_free()) return solve_reduced_by_cg(b, y);
  const bool bordered = bordered_ready();
  if (!ok_) return false;
  auto solve = [&](const Eigen::VectorXd& rhs) {
    return bordered ? qp_.bordered->solve(rhs) : factor_ ? factor_->solve(rhs) : single_factor_->solve(rhs);
  };
  y = solve(b);
  y += solve(b - refinement_.product(qp_, step_.directions, y));
  return true;
}

// solve_reduced() for the columns of B at once: the factor (or the bordered solver's factor and
// cache) and Q read once for all of them instead of once per column — a body of many parts held by
// contact asks for k = 6 per part (144 for 24 loose blocks).
bool RadiusSensitivity::solve_reduced_columns(const Eigen::MatrixXd& B, Eigen::MatrixXd& Y, double refined_to,
                                              int refinements) {
  if (qp_.matrix_free()) {
    Y.resize(B.rows(), B.cols());
    for (Eigen::Index j = 0; j < B.cols(); ++j) {
      Eigen::VectorXd y;
      if (!solve_reduced_by_cg(B.col(j), y)) return false;
      Y.col(j) = y;
    }
    return true;
  }
  const bool bordered = bordered_ready();
  if (!ok_) return false;
  auto solve = [&](const Eigen::MatrixXd& R) {
    return bordered  ? qp_.bordered->solve_columns(R)
           : factor_ ? factor_->solve_columns(R)
                     : single_factor_->solve_columns(R);
  };
  // Refined in double while the corrections shrink and are more than `refined_to` of the answer
  // (in each column), at most kMaxRefinements steps: a single factor of an ill-conditioned Q cuts the
  // error by only about cond(Q)·ε_single per step, and the equality loop's Newton steps on μ are only
  // as good as this Jacobian. One step, as before, where Q is well conditioned.
  // Several columns refined together (the joint Newton steps of equality_newton.hpp: k + 1 of them,
  // a first product through Q being most of a step's time): A's entries kept in double for them.
  if (single_factor_) refinement_.keep(qp_, step_.directions);
  Y = solve(B);
  double last = INFINITY;
  for (int step = 0; step < refinements; ++step) {
    const Eigen::MatrixXd correction = solve(B - refinement_.block_product(qp_, step_.directions, Y));
    products_ += static_cast<int>(B.cols());
    const double size = (correction.colwise().norm().array() / Y.colwise().norm().array().max(1e-300)).maxCoeff();
    if (!(size < last)) break;  // not contracting: the answer stays
    Y += correction;
    last = size;
    if (size <= refined_to) break;
  }
  return true;
}

// CG from the Galerkin projection of the solution onto the recycled basis: with A p_j orthonormal in
// A's inner product, y₀ = Σ (p_jᵀ b) p_j. A CG that does not converge leaves the sensitivity not ok().
bool RadiusSensitivity::solve_reduced_by_cg(const Eigen::VectorXd& b, Eigen::VectorXd& y) {
  y = Eigen::VectorXd::Zero(b.size());
  const double b_norm = b.norm();
  if (!(b_norm > 0)) return true;
  for (const Eigen::VectorXd& p : recycled_) y += p.dot(b) * p;
  const ReducedCgResult cg =
      solve_reduced_cg(qp_, step_.directions, b, kCgRelativeResidual * b_norm, kMaxCgProducts, y);
  products_ += cg.iterations;
  if (!cg.converged || !y.allFinite()) {
    ok_ = false;
    return false;
  }
  remember(y, b);
  return true;
}

// p made A-orthogonal to the basis (A p taken as the right-hand side it solved: equal to CG's
// tolerance), then A-normalized; dropped when little of it is new. The oldest goes when it is full.
void RadiusSensitivity::remember(Eigen::VectorXd p, Eigen::VectorXd Ap) {
  const double energy = p.dot(Ap);
  for (std::size_t j = 0; j < recycled_.size(); ++j) {
    const double c = recycled_products_[j].dot(p);
    p -= c * recycled_[j];
    Ap -= c * recycled_products_[j];
  }
  const double left = p.dot(Ap);
  if (!(left > 1e-12 * energy)) return;
  if (static_cast<int>(recycled_.size()) == kRecycledSolutions) {
    recycled_.erase(recycled_.begin());
    recycled_products_.erase(recycled_products_.begin());
  }
  recycled_.push_back(p / std::sqrt(left));
  recycled_products_.push_back(Ap / std::sqrt(left));
}

// Z = A⁻¹DᵀGᵀ in one blocked solve, and G D Z, decomposed (rank-revealing: rows of G that no free
// direction moves — a slide where no disc slides or sticks — give no dμ).
bool RadiusSensitivity::prepare_equality() {
  if (Z_.cols() == G_.rows()) return true;
  Eigen::MatrixXd Z;
  if (!solve_reduced_columns(restrict_columns(step_.directions, G_.transpose()), Z)) return false;
  GDZ_matrix_ = G_ * prolong(step_.directions, Z, qp_.size());
  GDZ_.compute(GDZ_matrix_);
  Z_ = std::move(Z);  // only once complete: a failed solve leaves it unprepared
  return true;
}

std::optional<Eigen::MatrixXd> RadiusSensitivity::solve_columns(const Eigen::MatrixXd& B, double correction,
                                                                int refinements) {
  if (!ok_) return std::nullopt;
  if (step_.directions.empty()) return Eigen::MatrixXd(0, B.cols());
  Eigen::MatrixXd Y;
  if (!solve_reduced_columns(B, Y, correction, refinements) || !Y.allFinite()) return std::nullopt;
  return Y;
}

std::optional<Eigen::MatrixXd> RadiusSensitivity::equality_response() {
  if (!ok_ || G_.rows() == 0) return std::nullopt;
  if (step_.directions.empty()) return Eigen::MatrixXd::Zero(G_.rows(), G_.rows());  // nothing moves
  if (!prepare_equality()) return std::nullopt;
  return GDZ_matrix_;
}

// dλ in the problem's variables (dμ of the scaled problem, its radii c / s_t), then mapped back.
Eigen::VectorXd RadiusSensitivity::apply(const Eigen::VectorXd& dc) {
  Eigen::VectorXd dlambda = Eigen::VectorXd::Zero(qp_.size());
  if (dmu_.size()) dmu_.setZero();
  if (!qp_.matrix_free()) products_ += kProductsPerApply;
  if (!ok_ || !qp_.with_friction) return dlambda;
  for (int i = 0; i < qp_.r; ++i) {
    const int a = qp_.layout().t1(i), b = qp_.layout().t2(i);
    const double dc_i = scale_.size() ? dc[i] / scale_[a] : dc[i];  // the scaled radius is c / s_t
    dlambda[a] = dc_i * nu_[a];
    dlambda[b] = dc_i * nu_[b];
  }
  if (!step_.directions.empty()) {
    Eigen::VectorXd dy;
    if (qp_.matrix_free()) ++products_;
    if (!solve_reduced(-restrict_to(step_.directions, qp_.apply(dlambda)), dy))
      return Eigen::VectorXd::Zero(qp_.size());
    if (G_.rows()) {  // μ moves so that G dλ = 0
      if (!prepare_equality()) return Eigen::VectorXd::Zero(qp_.size());
      dmu_ = GDZ_.solve(G_ * (dlambda + prolong(step_.directions, dy, qp_.size())));
      dy -= Z_ * dmu_;
    }
    dlambda += prolong(step_.directions, dy, qp_.size());
  }
  return scale_.size() ? Eigen::VectorXd(dlambda.cwiseProduct(scale_)) : dlambda;
}

}  // namespace contact3d
