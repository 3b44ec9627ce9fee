#include "qp/dual_qp_solver.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "linalg/dual_operator.hpp"
#include "linalg/symmetric_product.hpp"
#include "qp/hybrid_qp.hpp"
#include "qp/reduced_cg.hpp"
#include "qp/ssn.hpp"

namespace contact3d {

bool uses_single_products(QpPrecision precision, int multipliers) {
  return precision == QpPrecision::Mixed || (precision == QpPrecision::Auto && multipliers >= kMixedPrecisionMinSize);
}

DualQpSolver::DualQpSolver(const DenseView& Q, const Eigen::VectorXd& h, int r, bool with_friction, double q_norm,
                           const QpSettings& settings, std::shared_ptr<DualOperatorFactor> factor)
    : settings_(settings), h_(h) {
  qp_.Q = DenseViewPtr(Q);
  qp_.h = h;
  qp_.r = r;
  qp_.with_friction = with_friction;
  qp_.radius = Eigen::VectorXd::Zero(r);
  qp_.q_norm = 1.05 * q_norm;  // the estimate is a Rayleigh quotient, from below
  const bool single = uses_single_products(settings.precision, qp_.size());
  if (settings.scaling == QpScaling::Jacobi) jacobi_.emplace(qp_, !single);
  if (single) {
    const BoxDiscQP& solved = jacobi_ ? jacobi_->scaled(qp_.radius) : qp_;
    // Ŝ Q Ŝ has a diagonal of at most 1, so its entries are at most 1 in size: no scale needed in
    // float, and its norm comes from the single copy (half the bytes of the 50 products in double).
    single_scale_ = jacobi_ ? 1.0 : solved.q_norm > 0 ? solved.q_norm : 1.0;
    float* spare = factor && factor->in_single ? factor->in_single->spare_upper() : nullptr;
    if (spare) {
      single_ = upper_triangle_in_single(*solved.Q, single_scale_, solved.scale, spare, qp_.size());
      single_holder_ = factor;
    } else {
      q_single_ = lower_triangle_in_single(*solved.Q, single_scale_, solved.scale);
      single_ = &q_single_;
    }
    if (jacobi_) jacobi_->set_norm(1.05 * estimate_norm(single_, single_scale_));
  }
  if (settings.newton_systems == NewtonSystems::Auto)
    bordered_ = make_bordered_newton(std::move(factor),
                                     jacobi_ ? jacobi_->scale() : Eigen::VectorXd(Eigen::VectorXd::Ones(qp_.size())));
}

DualQpSolver::DualQpSolver(MatrixFreeQ Q, const Eigen::VectorXd& h, int r, bool with_friction, double q_norm,
                           const QpSettings& settings)
    : settings_(settings), h_(h) {
  settings_.precision = QpPrecision::Double;  // no single copy of Q to factor reduced systems in
  qp_.product = std::move(Q.product);
  if (uses_single_products(settings.precision, static_cast<int>(Q.diagonal.size()))) {
    qp_.single_product = std::move(Q.single_product);
    qp_.single_block_product = std::move(Q.single_block_product);
  }
  qp_.block_product = std::move(Q.block_product);
  qp_.q_diagonal = std::move(Q.diagonal);
  qp_.coarse_group = std::move(Q.coarse_group);
  qp_.lumped = std::move(Q.lumped);
  if (!qp_.coarse_group.empty()) qp_.coarse_products = std::make_shared<CoarseProducts>();
  qp_.h = h;
  qp_.r = r;
  qp_.with_friction = with_friction;
  qp_.radius = Eigen::VectorXd::Zero(r);
  qp_.q_norm = 1.05 * q_norm;  // the estimate is a Rayleigh quotient, from below
  if (settings_.scaling != QpScaling::Jacobi) return;
  // The scaled norm from single products where there are any (half the bytes of 50 products).
  const bool single = static_cast<bool>(qp_.single_product);
  jacobi_.emplace(qp_, !single);
  if (!single) return;
  const BoxDiscQP& scaled = jacobi_->scaled(qp_.radius);
  jacobi_->set_norm(1.05 *
                    estimate_norm(qp_.size(), [&scaled](const Eigen::VectorXd& v) { return scaled.apply_single(v); }));
}

BoxDiscQP DualQpSolver::solved_problem() {
  BoxDiscQP problem = jacobi_ ? jacobi_->scaled(qp_.radius) : qp_;
  if (single_) {
    problem.Q_single = single_;
    problem.single_scale = single_scale_;
  }
  problem.bordered = bordered_.get();
  return problem;
}

RadiusSensitivity DualQpSolver::radius_sensitivity(const Eigen::VectorXd& lambda) {
  const bool single = uses_single_products(settings_.precision, qp_.size());
  if (!jacobi_) return {solved_problem(), lambda, single, {}, G_};
  return {solved_problem(), jacobi_->to_scaled(lambda), single, jacobi_->scale(), G_};
}

QpResult DualQpSolver::solve(const Eigen::VectorXd& radius, Eigen::VectorXd& lambda, double rtol) {
  return has_equality() ? solve_with_equality(radius, lambda, rtol) : solve_for_linear_term(radius, lambda, rtol);
}

void DualQpSolver::set_equality(Eigen::MatrixXd G, Eigen::VectorXd e) {
  G_ = std::move(G);
  e_ = std::move(e);
  mu_ = Eigen::VectorXd::Zero(G_.rows());
  jacobian_.resize(0, 0);
}

void DualQpSolver::set_linear_term(const Eigen::VectorXd& h) {
  qp_.h = h;
  if (jacobi_) jacobi_->set_linear_term(h);
}

namespace {

constexpr int kMaxEqualitySteps = 50;
// Inner solves a search for the concave dual's maximum along one step may take.
constexpr int kMaxLineSearchSteps = 30;
// Outer steps of the augmented Lagrangian, the fallback of the equalities' Newton steps.
constexpr int kMaxAugmentedSteps = 40;
// It stops where ρ has grown 1e8 times without balancing the loads (a body the contact cannot hold),
// or past max(20 × the products of the Newton steps before it, 20 000) products.
constexpr double kAugmentedRhoGrowth = 1e8;
constexpr long kAugmentedBudgetFactor = 20;
constexpr long kAugmentedMinBudget = 20000;
// Below this ‖F‖/‖e‖ a step that finds no descent is the inner solves' rounding, not a failure.
constexpr double kEqualityNoiseFloor = 1e-7;
// The tightest tolerance the inner solves of the equality constraints are taken to when the loads
// stay unbalanced above kEqualityNoiseFloor (the double-precision floor of a projected gradient).
constexpr double kTightestInnerRtol = 1e-12;

// 1 / ‖row‖ of each row of G (1 for a zero row): G's rows are forces and moments, and a motion held
// only by small cells (a ball's torsion, held by the friction of millimetre cells at its pole) has a
// row orders of magnitude below the translations held by large cells far from the contact. The rank
// of G and the blindness of the equalities' Jacobian are judged in these units.
Eigen::VectorXd unit_row_scale(const Eigen::MatrixXd& G) {
  return G.rowwise().norm().unaryExpr([](double n) { return n > 0 ? 1 / n : 1.0; });
}

// The orthogonal projector onto the range of `G` (k × k): the part of Gλ − e that λ can move, its
// rank decided on S G with unit rows (range(G) = S⁻¹ range(S G)).
Eigen::MatrixXd range_projector(const Eigen::MatrixXd& G) {
  const Eigen::VectorXd scale = unit_row_scale(G);
  const Eigen::MatrixXd scaled = scale.asDiagonal() * G;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled * scaled.transpose());
  const double largest = eig.eigenvalues().size() ? eig.eigenvalues().maxCoeff() : 0.0;
  std::vector<Eigen::Index> kept;
  for (Eigen::Index j = 0; j < eig.eigenvalues().size(); ++j)
    if (largest > 0 && eig.eigenvalues()[j] > 1e-12 * largest) kept.push_back(j);
  if (kept.empty()) return Eigen::MatrixXd::Zero(G.rows(), G.rows());
  const Eigen::MatrixXd basis = scale.cwiseInverse().asDiagonal() * eig.eigenvectors()(Eigen::all, kept);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(basis);
  const Eigen::MatrixXd U = qr.householderQ() * Eigen::MatrixXd::Identity(G.rows(), basis.cols());
  return U * U.transpose();
}

// The problem with ½‖A x‖² added to its objective (A: k × m, k <= 6): its operator becomes Q + AᵀA,
// applied as a product (Q's factor, single copy and coarse space know nothing of AᵀA), so the Newton
// steps solve their reduced systems by CG with the diagonal. The augmented Lagrangian's inner problem.
BoxDiscQP with_penalty(const BoxDiscQP& problem, const Eigen::MatrixXd& A) {
  auto base = std::make_shared<const BoxDiscQP>(problem);
  BoxDiscQP penalized;
  penalized.product = [base, A](const Eigen::VectorXd& v) {
    return Eigen::VectorXd(base->apply(v) + A.transpose() * (A * v));
  };
  penalized.q_diagonal = base->diagonal() + A.colwise().squaredNorm().transpose();
  penalized.h = problem.h;
  penalized.r = problem.r;
  penalized.with_friction = problem.with_friction;
  penalized.radius = problem.radius;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A);
  const double a = svd.singularValues().size() ? svd.singularValues()[0] : 0.0;
  penalized.q_norm = problem.q_norm + a * a;
  return penalized;
}

}  // namespace

// The multipliers that can carry force in a solve with these radii: every normal one, a cell's
// tangential pair only where its disc has a radius (none in a frictionless solve, e.g. Coulomb's first).
Eigen::MatrixXd DualQpSolver::reachable_columns(const Eigen::VectorXd& radius) const {
  Eigen::MatrixXd G = G_;
  if (qp_.with_friction)
    for (int i = 0; i < qp_.r; ++i)
      if (!(radius[i] > 0)) G.col(qp_.r + i).setZero(), G.col(2 * qp_.r + i).setZero();
  return G;
}

QpResult DualQpSolver::solve_with_equality(const Eigen::VectorXd& radius, Eigen::VectorXd& lambda, double rtol) {
  const Eigen::Index k = G_.rows();
  double inner_rtol = std::min(1e-2 * rtol, 1e-8);
  QpResult total;
  total.status = QpStatus::Converged;
  bool inner_failed = false;
  // F(μ) = Gλ(μ) − e, λ(μ) warm-started from what `lam` holds.
  const auto F_at = [&](const Eigen::VectorXd& mu, Eigen::VectorXd& lam) {
    set_linear_term(h_ - G_.transpose() * mu);
    const QpResult r = solve_for_linear_term(radius, lam, inner_rtol);
    add_work(total, r);
    if (r.status != QpStatus::Converged) inner_failed = true;
    return Eigen::VectorXd(G_ * lam - e_);
  };
  if (lambda.size() != qp_.size()) lambda = Eigen::VectorXd::Zero(qp_.size());
  // Only the part of F in the range of the columns that can carry force is driven to 0 (P F); the
  // rest — a slide's loads where no disc has a radius — stays in equality_residual() for the caller.
  const Eigen::MatrixXd G_reach = qp_.with_friction ? reachable_columns(radius) : G_;
  const Eigen::MatrixXd P = range_projector(G_reach);
  const auto reach = [&P](const Eigen::VectorXd& F) { return (P * F).norm(); };
  if (reach_projector_.rows() != k || !reach_projector_.isApprox(P))
    jacobian_.resize(0, 0);  // other columns: measure again
  reach_projector_ = P;
  Eigen::VectorXd F = F_at(mu_, lambda);
  // F = ∇φ of the concave dual φ(μ) = min over λ of ½λᵀQλ − λᵀh + μᵀ(Gλ − e), so along a step s
  // g(t) = (P F(μ + t s))ᵀ s decreases. Where a step overshoots — g > 0 at its start, < 0 at its end,
  // as when friction is saturated on both sides of a stick state whose window in μ is narrow, and the
  // loads flip from one side to the other — φ's maximum along it lies inside: found by false position
  // (Illinois) on g, to 1% of g(0), and taken (φ rises). Returns false where s does not overshoot.
  const auto maximize_along = [&](const Eigen::VectorXd& step, const Eigen::VectorXd& F_end,
                                  const Eigen::VectorXd& lambda_end) {
    const double g0 = (P * F).dot(step), g1 = (P * F_end).dot(step);
    if (!(g0 > 0 && g1 < 0)) return false;
    double t_lo = 0, g_lo = g0, t_hi = 1, g_hi = g1;
    Eigen::VectorXd mu_best = mu_ + step, lam_best = lambda_end, F_best = F_end;
    double g_best = g1;
    int side = 0;
    for (int it = 0; it < kMaxLineSearchSteps && std::abs(g_best) > 1e-2 * g0 && !inner_failed; ++it) {
      const double t = (t_lo * g_hi - t_hi * g_lo) / (g_hi - g_lo);
      Eigen::VectorXd mu_t = mu_ + t * step, lam_t = g_lo > -g_hi ? lambda_end : lambda;
      const Eigen::VectorXd F_t = F_at(mu_t, lam_t);
      const double g = (P * F_t).dot(step);
      if (std::abs(g) < std::abs(g_best)) mu_best = mu_t, lam_best = lam_t, F_best = F_t, g_best = g;
      if (g > 0) {
        t_lo = t, g_lo = g;
        if (side == 1) g_hi /= 2;
        side = 1;
      } else {
        t_hi = t, g_hi = g;
        if (side == -1) g_lo /= 2;
        side = -1;
      }
    }
    mu_ = std::move(mu_best);
    lambda = std::move(lam_best);
    F = std::move(F_best);
    return true;
  };
  // The difference quotients' step: 1e-3 of μ, or of a rigid shift whose 𝔹Rμ is the size of h.
  const double G_max = G_.lpNorm<Eigen::Infinity>();
  const double mu_unit = G_max > 0 && h_.lpNorm<Eigen::Infinity>() > 0 ? h_.lpNorm<Eigen::Infinity>() / G_max : 1.0;
  // The Jacobian −G D A⁻¹ DᵀGᵀ from the reduced system at λ, its active sets held
  // (radius_sensitivity.hpp: k reduced solves instead of k QP solves); by difference quotients where
  // that system cannot be solved.
  const auto measure_jacobian = [&] {
    set_linear_term(h_ - G_.transpose() * mu_);
    RadiusSensitivity at_lambda = radius_sensitivity(lambda);
    const std::optional<Eigen::MatrixXd> response = at_lambda.equality_response();
    total.hessian_products += at_lambda.products();
    if (response) {
      jacobian_ = -*response;
      return;
    }
    jacobian_.resize(k, k);
    for (Eigen::Index j = 0; j < k; ++j) {
      Eigen::VectorXd mu_j = mu_, lam = lambda;
      const double step = 1e-3 * std::max(std::abs(mu_[j]), mu_unit);
      mu_j[j] += step;
      jacobian_.col(j) = (F_at(mu_j, lam) - F) / step;
    }
  };
  // Where no contact force responds to a change of μ (the body hovers over its gaps, or touches at
  // too few cells to hold a tilt), F is flat along it and the Jacobian blind: μ then moves along the
  // rigid shift that full contact would take (dμ = (G D⁻¹ Gᵀ)⁻¹ F, D = diag Q), as far as the Jacobian
  // does not see it, to just past the next touch of a cell (where its gradient (Qλ − h + Gᵀμ)_i reaches
  // 0 with λ held), and the Jacobian is measured again there.
  const Eigen::VectorXd q_diagonal = qp_.diagonal();
  const Eigen::MatrixXd full_contact = G_reach * q_diagonal.cwiseInverse().asDiagonal() * G_reach.transpose();
  const auto jump_to_next_touch = [&](const Eigen::VectorXd& d) {
    // The QP's gradient at λ, Qλ − h + Gᵀμ, moves by Gᵀd per unit of the shift (λ held).
    const Eigen::VectorXd gradient = qp_.apply(lambda) - h_ + G_.transpose() * mu_, slope = G_.transpose() * d;
    double touch = INFINITY;
    for (int i = 0; i < qp_.r; ++i)
      if (lambda[i] == 0 && slope[i] < 0) touch = std::min(touch, std::max(-gradient[i] / slope[i], 0.0));
    if (!std::isfinite(touch)) return false;
    const Eigen::VectorXd step = (1.05 * touch + 0.05) * d;
    Eigen::VectorXd lambda_end = lambda;
    const Eigen::VectorXd F_end = F_at(mu_ + step, lambda_end);
    if (!maximize_along(step, F_end, lambda_end)) mu_ += step, lambda = std::move(lambda_end), F = F_end;
    return true;
  };
  // The Jacobian is judged blind along a direction in unit-row units (μ = S μ̂, Ĵ = S J S), as the rank
  // of G is: judged unscaled, a ball's torsion looked blind next to its lift and was jumped along.
  const Eigen::VectorXd row_scale = unit_row_scale(G_);
  const auto unseen_shift = [&] {
    const Eigen::VectorXd shift = full_contact.completeOrthogonalDecomposition().solve(P * F);
    if (jacobian_.rows() != k) return shift;
    const Eigen::MatrixXd scaled = row_scale.asDiagonal() * jacobian_ * row_scale.asDiagonal();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeFullV);
    Eigen::Index seen = 0;
    while (seen < k && svd.singularValues()[seen] > 1e-6 * svd.singularValues()[0]) ++seen;
    const Eigen::MatrixXd blind = svd.matrixV().rightCols(k - seen);
    const Eigen::VectorXd shift_scaled = row_scale.cwiseInverse().cwiseProduct(shift);
    return Eigen::VectorXd(row_scale.cwiseProduct(blind * (blind.transpose() * shift_scaled)));
  };
  if (reach(F) > 0 && qp_.r > 0 && lambda.head(qp_.r).cwiseAbs().maxCoeff() == 0) jump_to_next_touch(unseen_shift());
  const double F_scale = e_.norm() > 0 ? e_.norm() : std::max(G_.norm() * lambda.norm(), 1e-300);
  const double target = std::max(rtol, 1e-9) * F_scale;
  bool fresh_jacobian = false;
  if (jacobian_.rows() != k && reach(F) > target) {
    measure_jacobian();
    fresh_jacobian = true;
  }
  // The best iterate (least unbalanced) is what a solve that does not converge ends with: jumps to the
  // next touch may unbalance the loads for a while (the body tips onto another cell) and need not
  // come back.
  Eigen::VectorXd best_mu = mu_, best_lambda = lambda, best_F = F;
  const auto remember_best = [&] {
    if (reach(F) >= reach(best_F)) return;
    best_mu = mu_;
    best_lambda = lambda;
    best_F = F;
  };
  bool searched_since_descent = false;
  for (int step = 0; step < kMaxEqualitySteps && reach(F) > target && !inner_failed; ++step, remember_best()) {
    // Blindness is judged on a measured Jacobian only: Broyden's updates can flatten a direction the
    // contact does hold, and a jump along it throws away the balance reached.
    if (qp_.r > 0 && !fresh_jacobian && unseen_shift().norm() > 0) {
      measure_jacobian();
      fresh_jacobian = true;
    }
    if (const Eigen::VectorXd blind = unseen_shift(); qp_.r > 0 && blind.norm() > 0 && jump_to_next_touch(blind)) {
      measure_jacobian();
      fresh_jacobian = true;
      continue;
    }
    // J ≈ −G·dλ/dh·Gᵀ is singular where the contact does not hold a motion: least squares there.
    const Eigen::VectorXd newton = jacobian_.completeOrthogonalDecomposition().solve(-P * F);
    bool accepted = false;
    Eigen::VectorXd F_full, lambda_full;  // at the full step
    for (double t = 1; t >= 1.0 / 256 && !accepted && !inner_failed; t /= 2) {
      Eigen::VectorXd mu_t = mu_ + t * newton, lam_t = lambda;
      const Eigen::VectorXd F_t = F_at(mu_t, lam_t);
      if (t == 1) F_full = F_t, lambda_full = lam_t;
      if (reach(F_t) >= (1 - 1e-4 * t) * reach(F)) continue;
      const Eigen::VectorXd s = t * newton, y = F_t - F;  // Broyden's update along the step taken
      jacobian_ += (y - jacobian_ * s) * s.transpose() / s.squaredNorm();
      mu_ = std::move(mu_t);
      lambda = std::move(lam_t);
      F = F_t;
      accepted = true;
    }
    // No step along it lowers ‖P F‖, but the full step overshoots φ's maximum along it: go there
    // (where the contact holds the motion again) and measure the Jacobian — once between two accepted
    // steps: where the Newton step from there fails too, the inner solves' rounding is the suspect.
    if (!accepted && !inner_failed && !searched_since_descent && maximize_along(newton, F_full, lambda_full)) {
      searched_since_descent = true;
      measure_jacobian();
      fresh_jacobian = true;
      continue;
    }
    if (accepted) searched_since_descent = false;
    if (!accepted && fresh_jacobian) {
      // Even a measured Jacobian gives no descent: F has no root, or the inner solves' rounding hides
      // it (an ill-conditioned Q: a ball on graded cells stalled at 1e-5 of the loads with inner
      // solves to 1e-8 and balanced them with 1e-12). Where the loads are not yet balanced to the
      // noise floor, solve tighter before concluding.
      if (inner_rtol > kTightestInnerRtol && reach(F) > kEqualityNoiseFloor * F_scale) {
        inner_rtol = std::max(1e-2 * inner_rtol, kTightestInnerRtol);
        F = F_at(mu_, lambda);
        measure_jacobian();
        continue;
      }
      break;
    }
    if (!accepted) measure_jacobian();
    fresh_jacobian = !accepted;
  }
  if (reach(F) > reach(best_F) && !inner_failed) {
    mu_ = best_mu;
    lambda = best_lambda;
    F = best_F;
  }
  // Newton's steps on μ left the loads unbalanced: the augmented Lagrangian from the best iterate,
  // slower but sure for a convex QP (its answer replaces the best iterate only where it is better).
  if (!inner_failed && reach(F) > std::max(target, kEqualityNoiseFloor * F_scale)) {
    Eigen::VectorXd augmented = lambda;
    const Eigen::VectorXd mu_before = mu_;
    const long budget =
        std::max(kAugmentedBudgetFactor * static_cast<long>(total.hessian_products), kAugmentedMinBudget);
    add_work(total, solve_with_augmented_lagrangian(radius, augmented, rtol, P,
                                                    std::max(target, kEqualityNoiseFloor * F_scale), budget));
    if (const Eigen::VectorXd F_augmented = G_ * augmented - e_; reach(F_augmented) < reach(F)) {
      lambda = std::move(augmented);
      F = F_augmented;
    } else {
      mu_ = mu_before;
    }
  }
  set_linear_term(h_ - G_.transpose() * mu_);  // the problem of the answer (for radius_sensitivity)
  equality_residual_ = F.norm() / F_scale;
  if (inner_failed)
    total.status = QpStatus::Breakdown;
  else if (reach(F) > std::max(target, kEqualityNoiseFloor * F_scale))
    total.status = QpStatus::IterationLimit;
  return total;
}

// The method of multipliers on L(λ, μ) = ½λᵀQλ − λᵀh + μᵀ(Gλ − e) + (ρ/2)‖Ĝλ − ê‖², Ĝλ = ê the
// reachable equalities with orthonormal rows in the solved (Jacobi-scaled) variables (P G S = U Σ Vᵀ,
// Ĝ = Σ⁻¹UᵀPGS = Vᵀ: G's rows are forces and moments of scales orders apart). Each outer step
// minimises L over the half-lines and discs for the current μ (the inner operator Q + ρĜᵀĜ,
// with_penalty), then μ += ρ U Σ⁻² Uᵀ (Gλ − e); λ then solves the QP without equalities for the new
// μ exactly, whatever Gλ − e. ρ starts at ‖Q‖ in the solved variables and grows ×10 whenever an
// outer step cuts ‖P(Gλ − e)‖ by less than 4.
QpResult DualQpSolver::solve_with_augmented_lagrangian(const Eigen::VectorXd& radius, Eigen::VectorXd& lambda,
                                                       double rtol, const Eigen::MatrixXd& P, double target,
                                                       long budget) {
  QpResult total;
  total.status = QpStatus::IterationLimit;
  const Eigen::MatrixXd PG = P * (jacobi_ ? Eigen::MatrixXd(G_ * jacobi_->scale().asDiagonal()) : G_);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(PG, Eigen::ComputeThinU);
  Eigen::Index rank = 0;
  while (rank < svd.singularValues().size() && svd.singularValues()[rank] > 1e-12 * svd.singularValues()[0]) ++rank;
  if (rank == 0) return total;
  const Eigen::VectorXd sigma = svd.singularValues().head(rank);
  const Eigen::MatrixXd U = svd.matrixU().leftCols(rank);
  const Eigen::MatrixXd G_hat = sigma.cwiseInverse().asDiagonal() * U.transpose() * PG;  // orthonormal rows
  const Eigen::MatrixXd W = U * sigma.cwiseAbs2().cwiseInverse().asDiagonal() * U.transpose();
  double rho = solved_problem().q_norm;
  const double inner_rtol = std::max(std::min(1e-2 * rtol, 1e-10), kTightestInnerRtol);
  Eigen::VectorXd F = G_ * lambda - e_;
  const double rho_limit = kAugmentedRhoGrowth * rho;
  for (int step = 0;
       step < kMaxAugmentedSteps && (P * F).norm() > target && rho <= rho_limit && total.hessian_products < budget;
       ++step) {
    const double before = (P * F).norm();
    const Eigen::MatrixXd A = std::sqrt(rho) * G_hat;
    set_linear_term(h_ - G_.transpose() * mu_ + rho * G_.transpose() * (W * e_));
    const QpResult inner = solve_for_linear_term(radius, lambda, inner_rtol, &A);
    add_work(total, inner);
    if (inner.status != QpStatus::Converged) return total;
    F = G_ * lambda - e_;
    mu_ += rho * (W * F);
    if ((P * F).norm() > 0.25 * before) rho *= 10;
  }
  jacobian_.resize(0, 0);  // measured again by the next solve
  if ((P * F).norm() <= target) total.status = QpStatus::Converged;
  return total;
}

QpResult DualQpSolver::solve_for_linear_term(const Eigen::VectorXd& radius, Eigen::VectorXd& lambda, double rtol,
                                             const Eigen::MatrixXd* penalty) {
  if (qp_.with_friction) qp_.radius = radius;
  if (lambda.size() != qp_.size()) lambda = Eigen::VectorXd::Zero(qp_.size());  // no warm start
  const BoxDiscQP problem = penalty ? with_penalty(solved_problem(), *penalty) : solved_problem();
  Eigen::VectorXd x = jacobi_ ? jacobi_->to_scaled(lambda) : lambda;
  QpResult result;
  if (progress_) progress_->restart();
  if (settings_.variant == QpVariant::Auto) {
    HybridSettings hybrid;
    hybrid.rtol = rtol;
    hybrid.max_iterations = settings_.max_iterations;
    hybrid.progress = progress_;
    result = solve_hybrid(problem, x, hybrid);
  } else if (settings_.variant == QpVariant::Ssn) {
    SsnSettings ssn;
    ssn.rtol = rtol;
    ssn.max_iterations = settings_.max_iterations;
    ssn.progress = progress_;
    result = solve_ssn(problem, x, ssn);
  } else {
    MpgpSettings mpgp;
    mpgp.rtol = rtol;
    mpgp.max_iterations = settings_.max_iterations;
    mpgp.progress = progress_;
    mpgp.expansion =
        settings_.variant == QpVariant::MpgpProjectedCG ? ExpansionKind::ProjectedCG : ExpansionKind::FullGradient;
    result = solve_mpgp(problem, x, mpgp);
  }
  lambda = jacobi_ ? jacobi_->from_scaled(x) : x;
  return result;
}

}  // namespace contact3d
