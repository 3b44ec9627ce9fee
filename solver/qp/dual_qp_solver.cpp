#include "qp/dual_qp_solver.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "linalg/dual_operator.hpp"
#include "linalg/symmetric_product.hpp"
#include "qp/equality_newton.hpp"
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
    bordered_ = make_bordered_newton(
        std::move(factor), jacobi_ ? jacobi_->scale() : Eigen::VectorXd(Eigen::VectorXd::Ones(qp_.size())), qp_.Q);
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
// A full Newton step on μ that leaves more than this share of ‖P F‖ is slow: the next step measures
// the Jacobian instead of trusting Broyden's update (the free thin slab with 4 800 multipliers: six
// inner solves at 1e-12 and 4 373 products without, four and 3 235 with; dual solve 47.6 → 30.5 s).
constexpr double kSlowFullStep = 0.1;
// Below this ‖F‖/scale (balance_scale) a step that finds no descent is the inner solves' rounding, not a failure.
constexpr double kEqualityNoiseFloor = 1e-7;
// Loads along the equalities' motions below this share of the contact forces' size along them
// (‖G‖‖λ‖) are balanced to that size instead of to their own: the inner solves' rounding of Gλ is
// 1e-12 … 1e-8 of it, so their share of kEqualityNoiseFloor stays attainable.
constexpr double kRoundingLoads = 1e-4;
// The tightest tolerance the inner solves of the equality constraints are taken to when the loads
// stay unbalanced above kEqualityNoiseFloor (the double-precision floor of a projected gradient).
constexpr double kTightestInnerRtol = 1e-12;
// Inner solves asked less than this take their MPGP products in double. Each of the hybrid's windows
// (25 iterations here) is a new MPGP solve whose gradient carries the rounding of its single-precision
// products (roundoff 6e-8), and MPGP's own switch to double after repeated false stops never fires
// within one: random body 51 of pipeline/random_bodies.py (a plate held by contact alone on an incline
// beyond its slip-weakening friction, 2 916 multipliers) with two BLAS threads ran an inner solve at
// 1e-10 with ‖gᴾ‖ between 6e-10 and 5e-9 of ‖h‖ for over 10 000 products, killed at 600 s; in double it
// is refused in 20-27 s. Only here: the slender strip asked 1e-12 and 1e-13 by the user (ctest
// strip_dual_solve_reaches_its_tolerance) reaches its rounding floor sooner with single products (55 416
// iterations in double against at most 20 000).
constexpr double kSingleTightestInnerRtol = 1e-9;
// A motion's row of G whose reachable columns hold less than this share of it: rounding, unreachable.
constexpr double kUnreachableRow = 1e-12;

// 1 / ‖row‖ of each row of G (1 for a zero row): G's rows are forces and moments, and a motion held
// only by small cells (a ball's torsion, held by the friction of millimetre cells at its pole) has a
// row orders of magnitude below the translations held by large cells far from the contact. The rank
// of G and the blindness of the equalities' Jacobian are judged in these units.
Eigen::VectorXd unit_row_scale(const Eigen::MatrixXd& G) {
  return G.rowwise().norm().unaryExpr([](double n) { return n > 0 ? 1 / n : 1.0; });
}

// An orthonormal basis (k × r) of the range of `G`, its rank decided on S G with unit rows
// (range(G) = S⁻¹ range(S G)).
Eigen::MatrixXd range_basis(const Eigen::MatrixXd& G) {
  const Eigen::VectorXd scale = unit_row_scale(G);
  const Eigen::MatrixXd scaled = scale.asDiagonal() * G;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled * scaled.transpose());
  const double largest = eig.eigenvalues().size() ? eig.eigenvalues().maxCoeff() : 0.0;
  std::vector<Eigen::Index> kept;
  for (Eigen::Index j = 0; j < eig.eigenvalues().size(); ++j)
    if (largest > 0 && eig.eigenvalues()[j] > 1e-12 * largest) kept.push_back(j);
  if (kept.empty()) return Eigen::MatrixXd::Zero(G.rows(), 0);
  const Eigen::MatrixXd basis = scale.cwiseInverse().asDiagonal() * eig.eigenvectors()(Eigen::all, kept);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(basis);
  return qr.householderQ() * Eigen::MatrixXd::Identity(G.rows(), basis.cols());
}

// An orthonormal basis C (k × r) of the balance conditions c, cᵀ(Gλ − e) = 0, that the multipliers
// which can carry force (the columns of `G_reach`, the others of `G` zeroed) can meet. Where they reach
// every motion, all of them. Where some motions N = null(G_reachᵀ) are seen by none of them (Coulomb's
// frictionless first solve: a slide in the plane), the loads along N stay unbalanced, and the
// conditions kept are the motions whose work on the dropped multipliers is orthogonal to N's,
// (Gᵀc)·(Gᵀn) = 0: for a flat face, the motions with no tangential trace, e.g. the tilt about an axis
// in the foundation's plane. The orthogonal complement of N instead depends on the motions' basis: a
// tilt about the centroid's axis, its tangential trace included, left the frictionless solve to
// balance a moment that friction carries later, and bodies with shear of 3-6% of their pressure were
// refused as tipping.
Eigen::MatrixXd balance_conditions(const Eigen::MatrixXd& G, const Eigen::MatrixXd& G_reach) {
  const Eigen::MatrixXd reached = range_basis(G_reach);
  const Eigen::Index k = G.rows(), r = reached.cols();
  if (r == k) return Eigen::MatrixXd::Identity(k, k);
  if (r == 0) return reached;
  const Eigen::HouseholderQR<Eigen::MatrixXd> split(reached);
  const Eigen::MatrixXd unseen = (split.householderQ() * Eigen::MatrixXd::Identity(k, k)).rightCols(k - r);  // N
  const Eigen::MatrixXd work = G * (G.transpose() * unseen);  // k × (k − r): c ⊥ work keeps the conditions
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> kept(work);
  if (kept.rank() < k - r) return reached;  // N does no work at all (a frictionless body's slide)
  return (kept.householderQ() * Eigen::MatrixXd::Identity(k, k)).rightCols(r);
}

// An orthonormal basis (k × r) of S⁻¹ range(C): the rigid shifts μ = S x the conditions C allow, in
// the unit-row units x that blindness is judged in (the identity where C is).
Eigen::MatrixXd scaled_shifts(const Eigen::MatrixXd& C, const Eigen::VectorXd& row_scale) {
  if (C.cols() == C.rows()) return Eigen::MatrixXd::Identity(C.rows(), C.rows());
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(row_scale.cwiseInverse().asDiagonal() * C);
  return qr.householderQ() * Eigen::MatrixXd::Identity(C.rows(), C.cols());
}

// The problem with ½‖A x‖² added to its objective (A: k × m, k <= 6): its operator becomes Q + AᵀA,
// A as the problem's low-rank term (BoxDiscQP::low_rank), so Q's single copy and the bordered factor
// still serve (the Newton steps add AᵀA by a Woodbury update). The augmented Lagrangian's inner problem.
BoxDiscQP with_penalty(const BoxDiscQP& problem, const Eigen::MatrixXd& A) {
  BoxDiscQP penalized = problem;
  penalized.low_rank = A;
  // The coarse space's products are of Q alone: the penalized problem keeps a cache of its own.
  if (penalized.coarse_products) penalized.coarse_products = std::make_shared<CoarseProducts>();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A);
  const double a = svd.singularValues().size() ? svd.singularValues()[0] : 0.0;
  penalized.q_norm = problem.q_norm + a * a;
  return penalized;
}

// G in the variables the QP solvers work on: G S where the problem is Jacobi-scaled (λ = S x).
Eigen::MatrixXd in_solved_variables(const Eigen::MatrixXd& G, const std::optional<JacobiScaledQP>& jacobi) {
  return jacobi ? Eigen::MatrixXd(G * jacobi->scale().asDiagonal()) : G;
}

// G D⁻¹ Gᵀ (D = diag Q): how the equalities' residual responds to a rigid shift when every cell is
// in full contact (the step along motions the Jacobian is blind to).
Eigen::MatrixXd full_contact_response(const Eigen::MatrixXd& G, const Eigen::VectorXd& q_diagonal) {
  const Eigen::MatrixXd response = G * q_diagonal.cwiseInverse().asDiagonal() * G.transpose();
  return response;
}

}  // namespace

// The multipliers that can carry force in a solve with these radii: every normal one, a cell's
// tangential pair only where its disc has a radius (none in a frictionless solve, e.g. Coulomb's first).
// A motion whose row keeps only rounding of its whole row there (a slide in the foundation's plane,
// whose normal entries are 1e-17 of its tangential ones, the free motions being a computed basis) is
// unreachable: its row is zeroed, or the unit-row rank test of range_basis counts it, the loads
// along it are driven at by μ, and μ jumps along it by 1e10 with nothing moving (Coulomb's first solve
// of a brick held by contact alone, pushed along y: every equality step in vain, then refused).
Eigen::MatrixXd DualQpSolver::reachable_columns(const Eigen::VectorXd& radius) const {
  Eigen::MatrixXd G = G_;
  if (!qp_.with_friction) return G;
  for (int i = 0; i < qp_.r; ++i)
    if (!(radius[i] > 0)) G.col(qp_.r + i).setZero(), G.col(2 * qp_.r + i).setZero();
  for (Eigen::Index j = 0; j < G.rows(); ++j)
    if (G.row(j).norm() <= kUnreachableRow * G_.row(j).norm()) G.row(j).setZero();
  return G;
}

// One solve() with equality constraints (set_equality): Newton steps on μ, their state and each kind
// of step a method; run() reads as the algorithm. F(μ) = Gλ(μ) − e is the gradient of the concave
// dual φ(μ) = min over λ of ½λᵀQλ − λᵀh + μᵀ(Gλ − e); only its part P F in the range of the columns
// that can carry force is driven to 0 (the rest — a slide's loads where no disc has a radius — stays
// in equality_residual() for the caller).
class DualQpSolver::EqualitySolve {
 public:
  EqualitySolve(DualQpSolver& solver, const Eigen::VectorXd& radius, Eigen::VectorXd& lambda, double rtol)
      : s_(solver), radius_(radius), lambda_(lambda), rtol_(rtol), k_(solver.G_.rows()) {
    inner_rtol_ = std::min(1e-2 * rtol, 1e-8);
    total_.status = QpStatus::Converged;
    if (lambda_.size() != s_.qp_.size()) lambda_ = Eigen::VectorXd::Zero(s_.qp_.size());
    G_reach_ = s_.qp_.with_friction ? s_.reachable_columns(radius) : s_.G_;
    conditions_ = balance_conditions(s_.G_, G_reach_);
    P_ = conditions_ * conditions_.transpose();
    if (s_.reach_projector_.rows() != k_ || !s_.reach_projector_.isApprox(P_))
      s_.jacobian_.resize(0, 0);  // other columns: measure again
    s_.reach_projector_ = P_;
    // The difference quotients' step: 1e-3 of μ, or of a rigid shift whose 𝔹Rμ is the size of h.
    const double G_max = s_.G_.lpNorm<Eigen::Infinity>();
    const double h_max = s_.h_.lpNorm<Eigen::Infinity>();
    mu_unit_ = G_max > 0 && h_max > 0 ? h_max / G_max : 1.0;
    full_contact_ = full_contact_response(G_reach_, s_.qp_.diagonal());
    row_scale_ = unit_row_scale(s_.G_);
    scaled_shifts_ = scaled_shifts(conditions_, row_scale_);
  }

  QpResult run() {
    F_ = balance_at(s_.mu_, lambda_);
    if (reach(F_) > 0 && s_.qp_.r > 0 && lambda_.head(s_.qp_.r).cwiseAbs().maxCoeff() == 0)
      jump_to_next_touch(unseen_shift());  // nothing touches yet
    F_scale_ = balance_scale();
    target_ = std::max(rtol_, 1e-9) * F_scale_;
    const Eigen::VectorXd start_mu = s_.mu_, start_lambda = lambda_, start_F = F_;
    const Eigen::MatrixXd start_jacobian = s_.jacobian_;
    const double start_inner_rtol = inner_rtol_;
    if (reach(F_) > target_) try_joint_newton();
    step_on_mu();
    // The joint steps' best iterate is a start the steps on μ may still fail from (a block on an
    // incline at 1.02 times the friction it needs: 1.54% of the in-plane loads left unbalanced, where
    // from the QP's own start they balance): then they go again from that start, as before.
    if (from_joint_best_ && (inner_failed_ || reach(F_) > settled())) {
      s_.mu_ = start_mu, lambda_ = start_lambda, F_ = start_F;
      inner_rtol_ = start_inner_rtol;
      inner_failed_ = fresh_jacobian_ = slow_full_step_ = searched_since_descent_ = false;
      s_.jacobian_ = start_jacobian;
      step_on_mu();
    }
    if (!inner_failed_ && reach(F_) > settled()) fall_back_to_augmented_lagrangian();
    s_.set_linear_term(s_.h_ - s_.G_.transpose() * s_.mu_);  // the problem of the answer (for radius_sensitivity)
    s_.equality_residual_ = F_.norm() / F_scale_;
    if (inner_failed_)
      total_.status = QpStatus::Breakdown;
    else if (reach(F_) > settled())
      total_.status = QpStatus::IterationLimit;
    return total_;
  }

  // Newton steps on μ (the Jacobian measured, or Broyden-updated along accepted steps) from (μ, λ, F)
  // until the loads are balanced to the target; ends at the least unbalanced iterate.
  void step_on_mu() {
    if (s_.jacobian_.rows() != k_ && reach(F_) > target_) measure_jacobian();
    best_mu_ = s_.mu_, best_lambda_ = lambda_, best_F_ = F_;
    for (int step = 0; step < kMaxEqualitySteps && reach(F_) > target_ && !inner_failed_; ++step, remember_best()) {
      if (jumped_along_blind_motion()) continue;
      // A full step that cut ‖P F‖ less than tenfold: Broyden's secant is not keeping up with the
      // active sets, and the Jacobian is measured at the new λ. Every step would be too often: on the
      // ball of ctest ball_on_plane_lateral_load_augmented_lagrangian the measured Jacobians of the
      // stick-slip flips left 53.5% of the loads unbalanced where Broyden's balance them.
      if (slow_full_step_ && !fresh_jacobian_) measure_jacobian();
      slow_full_step_ = false;
      // J ≈ −G·dλ/dh·Gᵀ is singular where the contact does not hold a motion: least squares there.
      const Eigen::MatrixXd& C = conditions_;
      const Eigen::VectorXd newton = C * Eigen::MatrixXd(C.transpose() * s_.jacobian_ * C)
                                             .completeOrthogonalDecomposition()
                                             .solve(-C.transpose() * F_);
      const HalvedStep halved = take_halved_step(newton, !searched_since_descent_);
      if (halved.accepted) {
        searched_since_descent_ = fresh_jacobian_ = false;
        continue;
      }
      // No step along it lowers ‖P F‖, but the full step overshoots φ's maximum along it: go there
      // (where the contact holds the motion again) and measure the Jacobian — once between two
      // accepted steps: where the Newton step from there fails too, the inner solves' rounding is the suspect.
      if (!inner_failed_ && !searched_since_descent_ && maximize_along(newton, halved.F_full, halved.lambda_full)) {
        searched_since_descent_ = true;
        measure_jacobian();
        continue;
      }
      if (!fresh_jacobian_) {
        measure_jacobian();
        continue;
      }
      if (!tighten_inner_solves()) break;
    }
    if (reach(F_) > reach(best_F_) && !inner_failed_) s_.mu_ = best_mu_, lambda_ = best_lambda_, F_ = best_F_;
  }

 private:
  struct HalvedStep {
    bool accepted = false;
    Eigen::VectorXd F_full, lambda_full;  // at the full step
  };

  double reach(const Eigen::VectorXd& F) const { return (P_ * F).norm(); }
  // What ‖Gλ − e‖ is measured against: the loads along the motions, ‖e‖, or where they are a sum
  // that cancels (a symmetric body's loads along its free slide: rounding, 6.5e-9 N against 1e6 N of
  // contact force on a pressed shell), kRoundingLoads of the contact forces' size along them, ‖G‖‖λ‖;
  // the loads relative to their own rounding could never be balanced.
  double balance_scale() const {
    const double contact = s_.G_.norm() * lambda_.norm();
    return std::max({s_.e_.norm(), kRoundingLoads * contact, 1e-300});
  }
  // The level below which the loads count as balanced: the target, or the inner solves' noise floor.
  double settled() const { return std::max(target_, kEqualityNoiseFloor * F_scale_); }

  // Newton steps on λ and μ together (equality_newton.hpp), where Q is dense and the QP takes Newton
  // steps: each costs a reduced factorization where a step on μ alone costs a whole QP solve. Taken
  // where they balance the loads with λ solving its QP (true); otherwise the steps on μ go on from
  // where they were, or from the joint steps' best iterate where it is much better (its λ(μ) solved
  // again), the joint steps' work counted.
  bool try_joint_newton() {
    const QpVariant variant = s_.settings_.variant;
    if (s_.qp_.matrix_free() || conditions_.cols() == 0 || !(variant == QpVariant::Auto || variant == QpVariant::Ssn))
      return false;
    s_.set_linear_term(s_.h_ - s_.G_.transpose() * s_.mu_);
    const BoxDiscQP problem = s_.solved_problem();
    const bool scaled = s_.jacobi_.has_value();
    const Eigen::MatrixXd G = in_solved_variables(s_.G_, s_.jacobi_);
    EqualityNewtonSettings settings;
    settings.rtol = inner_rtol_;
    settings.balance_target = target_;
    settings.single_precision = uses_single_products(s_.settings_.precision, s_.qp_.size());
    const Eigen::VectorXd start = scaled ? s_.jacobi_->to_scaled(lambda_) : lambda_;
    EqualityNewtonResult joint = solve_equality_newton(problem, G, s_.e_, conditions_, start, settings);
    add_counts(total_, joint.work);
    if (!joint.converged && !joint.improved) {
      // Whole steps whose first target lay far from the answer: damped from the same start. A helper's
      // steel plate on a rubber layer (ν = 0.49) held by contact alone, pushed sideways, its first Coulomb
      // solve: the whole steps' merit 0.4 → 1.2e3 → 4e4 → 1.4e6, given up, and the steps on μ took
      // 3 671 QP iterations (7 300 products); damped, 14 steps and 190 products.
      settings.damped = true;
      joint = solve_equality_newton(problem, G, s_.e_, conditions_, start, settings);
      add_counts(total_, joint.work);
    }
    if (!joint.converged) {
      if (joint.improved) {  // the steps on μ go on from its best iterate, λ(μ) solved there
        from_joint_best_ = true;
        s_.mu_ += joint.mu_shift;
        lambda_ = scaled ? s_.jacobi_->from_scaled(joint.lambda) : joint.lambda;
        F_ = balance_at(s_.mu_, lambda_);
      }
      return false;
    }
    s_.mu_ += joint.mu_shift;
    lambda_ = scaled ? s_.jacobi_->from_scaled(joint.lambda) : joint.lambda;
    F_ = s_.G_ * lambda_ - s_.e_;
    s_.jacobian_ = -joint.response;
    return true;
  }

  // F(μ) = Gλ(μ) − e, λ(μ) warm-started from what `lam` holds (and left there).
  Eigen::VectorXd balance_at(const Eigen::VectorXd& mu, Eigen::VectorXd& lam) {
    s_.set_linear_term(s_.h_ - s_.G_.transpose() * mu);
    const QpResult r = s_.solve_for_linear_term(radius_, lam, inner_rtol_, nullptr, true);
    add_work(total_, r);
    if (r.status != QpStatus::Converged) inner_failed_ = true;
    return s_.G_ * lam - s_.e_;
  }

  void take(Eigen::VectorXd mu, Eigen::VectorXd lambda, Eigen::VectorXd F) {
    s_.mu_ = std::move(mu);
    lambda_ = std::move(lambda);
    F_ = std::move(F);
  }

  void remember_best() {
    if (reach(F_) < reach(best_F_)) best_mu_ = s_.mu_, best_lambda_ = lambda_, best_F_ = F_;
  }

  // Along a step s, g(t) = (P F(μ + t s))ᵀ s decreases (φ is concave). Where the step overshoots — g > 0
  // at its start, < 0 at its end, as when friction is saturated on both sides of a stick state whose
  // window in μ is narrow, and the loads flip from one side to the other — φ's maximum along it lies
  // inside: found by false position (Illinois) on g, to 1% of g(0), and taken (φ rises). Returns false
  // where s does not overshoot.
  bool maximize_along(const Eigen::VectorXd& step, const Eigen::VectorXd& F_end, const Eigen::VectorXd& lambda_end) {
    const double g0 = (P_ * F_).dot(step), g1 = (P_ * F_end).dot(step);
    if (!(g0 > 0 && g1 < 0)) return false;
    double t_lo = 0, g_lo = g0, t_hi = 1, g_hi = g1;
    Eigen::VectorXd mu_best = s_.mu_ + step, lam_best = lambda_end, F_best = F_end;
    double g_best = g1;
    int side = 0;
    for (int it = 0; it < kMaxLineSearchSteps && std::abs(g_best) > 1e-2 * g0 && !inner_failed_; ++it) {
      const double t = (t_lo * g_hi - t_hi * g_lo) / (g_hi - g_lo);
      Eigen::VectorXd mu_t = s_.mu_ + t * step, lam_t = g_lo > -g_hi ? lambda_end : lambda_;
      const Eigen::VectorXd F_t = balance_at(mu_t, lam_t);
      const double g = (P_ * F_t).dot(step);
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
    take(std::move(mu_best), std::move(lam_best), std::move(F_best));
    return true;
  }

  // The Jacobian −G D A⁻¹ DᵀGᵀ from the reduced system at λ, its active sets held
  // (radius_sensitivity.hpp: k reduced solves instead of k QP solves); by difference quotients where
  // that system cannot be solved.
  void measure_jacobian() {
    fresh_jacobian_ = true;
    s_.set_linear_term(s_.h_ - s_.G_.transpose() * s_.mu_);
    RadiusSensitivity at_lambda = s_.radius_sensitivity(lambda_);
    const std::optional<Eigen::MatrixXd> response = at_lambda.equality_response();
    total_.hessian_products += at_lambda.products();
    if (response) {
      s_.jacobian_ = -*response;
      return;
    }
    s_.jacobian_.resize(k_, k_);
    for (Eigen::Index j = 0; j < k_; ++j) {
      Eigen::VectorXd mu_j = s_.mu_, lam = lambda_;
      const double step = 1e-3 * std::max(std::abs(s_.mu_[j]), mu_unit_);
      mu_j[j] += step;
      s_.jacobian_.col(j) = (balance_at(mu_j, lam) - F_) / step;
    }
  }

  // Where no contact force responds to a change of μ (the body hovers over its gaps, or touches at
  // too few cells to hold a tilt), F is flat along it and the Jacobian blind: μ then moves along the
  // rigid shift that full contact would take (dμ = (G D⁻¹ Gᵀ)⁻¹ F, D = diag Q), as far as the Jacobian
  // does not see it. The Jacobian is judged blind along a direction in unit-row units (μ = S μ̂,
  // Ĵ = S J S), as the rank of G is: judged unscaled, a ball's torsion looked blind next to its lift.
  Eigen::VectorXd unseen_shift() const {
    const Eigen::MatrixXd& C = conditions_;
    const Eigen::VectorXd shift =
        C *
        Eigen::MatrixXd(C.transpose() * full_contact_ * C).completeOrthogonalDecomposition().solve(C.transpose() * F_);
    if (s_.jacobian_.rows() != k_) return shift;
    const Eigen::MatrixXd& X = scaled_shifts_;
    const Eigen::MatrixXd scaled = X.transpose() * row_scale_.asDiagonal() * s_.jacobian_ * row_scale_.asDiagonal() * X;
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeFullV);
    const Eigen::Index n = X.cols();
    Eigen::Index seen = 0;
    while (seen < n && svd.singularValues()[seen] > 1e-6 * svd.singularValues()[0]) ++seen;
    const Eigen::MatrixXd blind = X * svd.matrixV().rightCols(n - seen);
    const Eigen::VectorXd shift_scaled = row_scale_.cwiseInverse().cwiseProduct(shift);
    return row_scale_.cwiseProduct(blind * (blind.transpose() * shift_scaled));
  }

  // μ along `d` to just past the next touch of a cell (where its gradient (Qλ − h + Gᵀμ)_i reaches 0
  // with λ held), or to φ's maximum along the way where it lies before. False where no cell touches.
  bool jump_to_next_touch(const Eigen::VectorXd& d) {
    // The QP's gradient at λ, Qλ − h + Gᵀμ, moves by Gᵀd per unit of the shift (λ held).
    const Eigen::VectorXd gradient = s_.qp_.apply(lambda_) - s_.h_ + s_.G_.transpose() * s_.mu_;
    const Eigen::VectorXd slope = s_.G_.transpose() * d;
    double touch = INFINITY;
    for (int i = 0; i < s_.qp_.r; ++i)
      if (lambda_[i] == 0 && slope[i] < 0) touch = std::min(touch, std::max(-gradient[i] / slope[i], 0.0));
    if (!std::isfinite(touch)) return false;
    const Eigen::VectorXd step = (1.05 * touch + 0.05) * d;
    Eigen::VectorXd lambda_end = lambda_;
    const Eigen::VectorXd F_end = balance_at(s_.mu_ + step, lambda_end);
    if (!maximize_along(step, F_end, lambda_end)) take(s_.mu_ + step, std::move(lambda_end), F_end);
    return true;
  }

  // Blindness is judged on a measured Jacobian only (Broyden's updates can flatten a direction the
  // contact does hold, and a jump along it throws away the balance reached); where it is blind, the
  // jump to the next touch, and the Jacobian measured there. True where μ jumped.
  bool jumped_along_blind_motion() {
    if (s_.qp_.r == 0) return false;
    if (!fresh_jacobian_ && unseen_shift().norm() > 0) measure_jacobian();
    const Eigen::VectorXd blind = unseen_shift();
    if (blind.norm() == 0 || !jump_to_next_touch(blind)) return false;
    measure_jacobian();
    return true;
  }

  // The Newton step, halved until ‖P F‖ falls (Armijo-like, down to 1/256), the Jacobian
  // Broyden-updated along the step taken. A full step that overshoots φ's maximum along it (g(0) > 0 >
  // g(1), maximize_along) without lowering ‖P F‖ is not halved where `search_overshoot`: the search
  // for that maximum, whose first trial is the half step, takes over. Where F flips across a narrow
  // stick window — a pressed shell held by contact alone, every cell of its contact strip slipping
  // the same way at the start, its 11 875 N of friction turning to −11 875 N over the full step — the
  // shorter steps all sit on the same side of the window (‖P F‖ unchanged) and halving them to 1/256
  // cost eight inner QP solves (480 of the solve's 1 227 iterations) before the search began.
  HalvedStep take_halved_step(const Eigen::VectorXd& newton, bool search_overshoot) {
    HalvedStep result;
    for (double t = 1; t >= 1.0 / 256 && !result.accepted && !inner_failed_; t /= 2) {
      Eigen::VectorXd mu_t = s_.mu_ + t * newton, lam_t = lambda_;
      const Eigen::VectorXd F_t = balance_at(mu_t, lam_t);
      if (t == 1) result.F_full = F_t, result.lambda_full = lam_t;
      if (reach(F_t) >= (1 - 1e-4 * t) * reach(F_)) {
        if (t == 1 && search_overshoot && (P_ * F_).dot(newton) > 0 && (P_ * F_t).dot(newton) < 0) break;
        continue;
      }
      slow_full_step_ = t == 1 && reach(F_t) > kSlowFullStep * reach(F_);
      const Eigen::VectorXd s = t * newton, y = F_t - F_;
      s_.jacobian_ += (y - s_.jacobian_ * s) * s.transpose() / s.squaredNorm();
      take(std::move(mu_t), std::move(lam_t), F_t);
      result.accepted = true;
    }
    return result;
  }

  // Even a measured Jacobian gives no descent: F has no root, or the inner solves' rounding hides it
  // (an ill-conditioned Q: a ball on graded cells stalled at 1e-5 of the loads with inner solves to
  // 1e-8 and balanced them with 1e-12). The inner solves are tightened (×1e-2, down to
  // kTightestInnerRtol) and F and J taken again, also where the loads are balanced to the noise floor
  // but not to the target (the ball's last Coulomb step stalled at 1.5e-8 of them with inner solves
  // at 7e-12, and went to 7e-12 with 1e-12); false where there is nothing left to tighten.
  bool tighten_inner_solves() {
    if (inner_rtol_ <= kTightestInnerRtol) return false;
    inner_rtol_ = std::max(1e-2 * inner_rtol_, kTightestInnerRtol);
    F_ = balance_at(s_.mu_, lambda_);
    measure_jacobian();
    return true;
  }

  // Newton's steps on μ left the loads unbalanced: the augmented Lagrangian from the best iterate,
  // slower but sure for a convex QP (its answer replaces the best iterate only where it is better).
  void fall_back_to_augmented_lagrangian() {
    Eigen::VectorXd augmented = lambda_;
    const Eigen::VectorXd mu_before = s_.mu_;
    const long budget =
        std::max(kAugmentedBudgetFactor * static_cast<long>(total_.hessian_products), kAugmentedMinBudget);
    add_work(total_, s_.solve_with_augmented_lagrangian(radius_, augmented, rtol_, P_, settled(), budget));
    if (const Eigen::VectorXd F_augmented = s_.G_ * augmented - s_.e_; reach(F_augmented) < reach(F_)) {
      lambda_ = std::move(augmented);
      F_ = F_augmented;
    } else {
      s_.mu_ = mu_before;
    }
  }

  DualQpSolver& s_;
  const Eigen::VectorXd& radius_;
  Eigen::VectorXd& lambda_;  // the caller's warm start, and the answer
  const double rtol_;
  const Eigen::Index k_;  // equality rows
  double inner_rtol_;     // the inner QPs' tolerance, tightened where rounding hides the descent
  QpResult total_;
  bool inner_failed_ = false;
  Eigen::MatrixXd G_reach_;         // G's reachable columns
  Eigen::MatrixXd conditions_, P_;  // the balance conditions C they can meet (balance_conditions), P = C Cᵀ
  Eigen::MatrixXd scaled_shifts_;   // scaled_shifts(C, row_scale_)
  Eigen::VectorXd F_;               // F at (mu_, lambda_)
  double mu_unit_ = 1;
  Eigen::MatrixXd full_contact_;  // G D⁻¹ Gᵀ over the reachable columns
  Eigen::VectorXd row_scale_;     // unit_row_scale(G)
  double F_scale_ = 1, target_ = 0;
  bool slow_full_step_ = false;          // the last accepted step was a full one that cut ‖P F‖ less than tenfold
  bool fresh_jacobian_ = false;          // the Jacobian was measured since the last accepted step
  bool searched_since_descent_ = false;  // maximize_along taken since the last accepted step
  bool from_joint_best_ = false;         // the steps on μ start from the joint steps' best iterate
  // The best iterate (least unbalanced) is what a solve that does not converge ends with: jumps to
  // the next touch may unbalance the loads for a while (the body tips onto another cell).
  Eigen::VectorXd best_mu_, best_lambda_, best_F_;
};

QpResult DualQpSolver::solve_with_equality(const Eigen::VectorXd& radius, Eigen::VectorXd& lambda, double rtol) {
  return EqualitySolve(*this, radius, lambda, rtol).run();
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
  const Eigen::MatrixXd PG = P * in_solved_variables(G_, jacobi_);
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
    const QpResult inner = solve_for_linear_term(radius, lambda, inner_rtol, &A, true);
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
                                             const Eigen::MatrixXd* penalty, bool of_equalities) {
  const bool single_products = !(of_equalities && rtol < kSingleTightestInnerRtol);
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
    hybrid.single_products = single_products;
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
    mpgp.single_products = single_products;
    mpgp.expansion =
        settings_.variant == QpVariant::MpgpProjectedCG ? ExpansionKind::ProjectedCG : ExpansionKind::FullGradient;
    result = solve_mpgp(problem, x, mpgp);
  }
  lambda = jacobi_ ? jacobi_->from_scaled(x) : x;
  return result;
}

}  // namespace contact3d
