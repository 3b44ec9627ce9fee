#include "qp/equality_newton.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <unordered_set>
#include <vector>

#include <Eigen/QR>

#include "qp/newton_system.hpp"
#include "qp/radius_sensitivity.hpp"

namespace contact3d {
namespace {

// The reduced solves are refined in double to a share of the answer (at most kRefinements steps):
// loosely while the active sets still change (the step is a guess of where they settle), tightly
// once they repeat, where the step must reach the inner solves' 1e-8 … 1e-12 (a single factor of an
// ill-conditioned Q gains only a few digits per refinement). On the free plate with 3 468
// multipliers the tight solves throughout cost 60 products a step.
constexpr double kRefinedWhileMoving = 1e-3, kRefinedSettled = 1e-12;
constexpr int kRefinements = 8;
// The steps are given up where the active sets come back to a set of an earlier step (not the last
// one: settled sets repeat), a cycle, or after this many steps without progress: a step makes
// progress where the merit reaches a new least value, or where the number of free directions moves
// the same way as in the step before (the sets sweep the contact zone's edge ring by ring). The merit
// may rise all through such a sweep: on the free plate with 4 800 multipliers and a frictionless
// solve, ‖F₁‖ went 0.41 → 0.63 → 0.56 while the cells in contact fell 1 101 → 559 in 21 steps, and the
// steps converged after 53 (4.8 s, where the steps on μ alone took 13 s). They are also given up
// after kMaxSteepRises steps (the first excepted: its start has F₁ = 0) that more than double ‖F‖:
// the sets then flip between two states (the free slab, 2 × 2 × 0.05 m with 4 800 multipliers: ‖F₁‖
// 0.46 → 1.15 → 0.41 → 1.11 → 0.38 …, where a cycle was seen only at the eighth step).
constexpr int kMaxStepsWithoutProgress = 20;
// Once the active sets repeat (settled), a step solves the same linear system again and only rounding
// is left to gain: such a step makes progress only where it at least halves the least merit so far, and
// the steps are given up after kMaxSettledStepsWithoutProgress that do not. A pressed plate held by
// contact alone (4 464 multipliers, cond(Q) 7e7, its inner solves asked 1e-12, one BLAS thread) sat at
// a merit of 1.73e-12 ± 5% for 25 settled steps, each a new least value by a hair, 1 587 products
// (11 s) before the 20 steps without a new least value ran out; the loop on μ then finished in 105.
constexpr double kSettledProgress = 0.5;
constexpr int kMaxSettledStepsWithoutProgress = 3;
// Steps given up with an iterate whose merit is under this share of the start's hand it to the caller
// (EqualityNewtonResult::improved). A free plate 1 × 1 × 0.02 m with 13 467 multipliers (cond(Q) 9e7)
// came down from its start to a merit of 8e-10 in 80 steps, then its active sets flipped on a few cells
// at the zone's edge (1 000 ↔ 1 005 ↔ 996 free directions), the merit rose twice over 4-fold and the
// steps were given up; the steps on μ started again from the start and took 800 s.
constexpr double kImprovedMerit = 0.25;
constexpr double kSteepRise = 2.0;
constexpr int kMaxSteepRises = 2;
// A damped step is halved at most this many times (down to 1/64 of the Newton step).
constexpr int kMaxHalvings = 6;

// A fingerprint of the active sets (which multipliers move, and along which pair).
std::size_t fingerprint(const std::vector<Direction>& d) {
  std::size_t seed = d.size();
  for (const Direction& x : d) {
    seed ^= std::hash<long long>{}(static_cast<long long>(x.a) * 1000003LL + x.b) + 0x9e3779b97f4a7c15ULL +
            (seed << 6) + (seed >> 2);
  }
  return seed;
}

bool same_directions(const std::vector<Direction>& a, const std::vector<Direction>& b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](const Direction& x, const Direction& y) {
           return x.a == y.a && x.b == y.b;
         });
}

// One solve_equality_newton() call: the iterate (λ, δμ), its product Qλ and merit; run() reads as the
// algorithm.
class JointNewton {
 public:
  JointNewton(const BoxDiscQP& problem, const Eigen::MatrixXd& G, const Eigen::VectorXd& e,
              const Eigen::MatrixXd& conditions, const Eigen::VectorXd& start, const EqualityNewtonSettings& settings)
      : qp_(problem),
        G_(G),
        e_(e),
        C_(conditions),
        settings_(settings),
        rho_(projection_scale(problem)),
        g_scale_(G.norm() > 0 ? G.norm() : 1.0),
        x_(start),
        delta_(Eigen::VectorXd::Zero(G.rows())) {}

  EqualityNewtonResult run() {
    project(qp_, x_);
    Qx_ = apply(x_);
    merit_ = merit(x_, Qx_, delta_);
    const double start_merit = merit_;
    best_x_ = x_, best_delta_ = delta_, best_merit_ = merit_;
    // The start is an exact solution of the QP for μ (F₁ = 0): progress is judged from the first step on.
    double best = INFINITY;
    int since_best = 0;
    long last_move = 0;  // the change in the number of free directions at the last step
    int steep_rises = 0;
    for (int step = 0; std::isfinite(merit_); ++step) {
      if (converged()) return result_;
      if (step == settings_.max_steps) break;
      Eigen::VectorXd x_target, delta_target;
      const long directions_before = static_cast<long>(last_directions_.size());
      if (!newton_target(x_target, delta_target)) break;
      ++result_.work.iterations;
      ++result_.work.newton_steps;
      const long moved = static_cast<long>(last_directions_.size()) - directions_before;
      const double merit_before = merit_;
      const double steep_merit = kSteepRise * kSteepRise * merit_before;  // ‖F‖ more than doubled
      take_full_step(x_target, delta_target);
      if (settings_.damped && merit_ > steep_merit) halve_back(merit_before);
      if (merit_ < best_merit_) best_x_ = x_, best_delta_ = delta_, best_merit_ = merit_;
      steep_rises += step > 0 && merit_ > steep_merit;
      const bool sweeping = moved != 0 && (moved > 0) == (last_move > 0);
      const bool progress = sweeping || merit_ < (settled_ ? kSettledProgress : 1.0) * best;
      since_best = progress ? 0 : since_best + 1;
      best = std::min(best, merit_);
      last_move = moved;
      const int patience = settled_ ? kMaxSettledStepsWithoutProgress : kMaxStepsWithoutProgress;
      if (since_best >= patience || cycled_ || steep_rises >= kMaxSteepRises) break;
    }
    result_.converged = false;
    if (best_merit_ < kImprovedMerit * start_merit) {
      project(qp_, best_x_);
      result_.improved = true;
      result_.lambda = std::move(best_x_);
      result_.mu_shift = std::move(best_delta_);
    }
    return result_;
  }

 private:
  Eigen::VectorXd apply(const Eigen::VectorXd& v) {
    ++result_.work.hessian_products;
    return qp_.apply(v);
  }
  // The linear term for the shift δ: h − Gᵀδ (the problem's own h being h − Gᵀμ).
  Eigen::VectorXd linear_term(const Eigen::VectorXd& delta) const { return qp_.h - G_.transpose() * delta; }
  Eigen::VectorXd balance(const Eigen::VectorXd& x) const { return C_ * (C_.transpose() * (G_ * x - e_)); }

  // ‖F₁‖² + (‖F₂‖ / ‖G‖)²: the QP's projection residual and the loads left, in λ's units.
  double merit(const Eigen::VectorXd& x, const Eigen::VectorXd& Qx, const Eigen::VectorXd& delta) const {
    Eigen::VectorXd z = x - rho_ * (Qx - linear_term(delta));
    project(qp_, z);
    return (x - z).squaredNorm() + (balance(x) / g_scale_).squaredNorm();
  }

  // Both tests at the feasible point P(λ): the QP's projected gradient for the linear term of μ + δμ,
  // and the loads along the kept conditions; the answer recorded where they hold.
  bool converged() {
    Eigen::VectorXd x = x_;
    project(qp_, x);
    const bool moved = !(x - x_).isZero(0);
    const Eigen::VectorXd Qx = moved ? apply(x) : Qx_;
    const Eigen::VectorXd h = linear_term(delta_);
    const GradientSplit split = split_gradient(qp_, x, Qx - h);
    const double pg = std::sqrt(split.free.squaredNorm() + split.chopped.squaredNorm());
    const double left = balance(x).norm();
    result_.work.projected_gradient = pg / std::max(h.norm(), 1e-300);
    if (!(pg <= settings_.rtol * h.norm() && left <= settings_.balance_target)) return false;
    result_.converged = true;
    result_.lambda = std::move(x);
    result_.mu_shift = delta_;
    result_.work.status = QpStatus::Converged;
    return true;
  }

  // The bordered Newton system at the active sets of z = λ − ρ g (see the header).
  bool newton_target(Eigen::VectorXd& x_target, Eigen::VectorXd& delta_target) {
    BoxDiscQP at_delta = qp_;
    at_delta.h = linear_term(delta_);
    RadiusSensitivity reduced(at_delta, x_, settings_.single_precision);
    ++result_.work.hessian_products;  // its z = λ − ρ g
    if (!reduced.ok()) return false;
    const ReducedStep& step = reduced.active_sets();
    const int m = qp_.size();
    const Eigen::Index k = G_.rows();
    Eigen::MatrixXd B(static_cast<Eigen::Index>(step.directions.size()), k + 1);
    B.col(0) = restrict_to(step.directions, at_delta.h - apply(step.lambda_fixed));
    B.rightCols(k) = restrict_columns(step.directions, G_.transpose());
    settled_ = same_directions(step.directions, last_directions_);
    if (!settled_) cycled_ = !seen_.insert(fingerprint(step.directions)).second;
    last_directions_ = step.directions;
    const std::optional<Eigen::MatrixXd> Y =
        reduced.solve_columns(B, settled_ ? kRefinedSettled : kRefinedWhileMoving, kRefinements);
    result_.work.hessian_products += reduced.products();
    if (!Y) return false;
    const Eigen::VectorXd y0 = Y->col(0);
    const Eigen::MatrixXd Z = Y->rightCols(k);
    result_.response = G_ * prolong(step.directions, Z, m);
    const Eigen::VectorXd left = G_ * (step.lambda_fixed + prolong(step.directions, y0, m)) - e_;
    const Eigen::VectorXd shift = C_ * Eigen::MatrixXd(C_.transpose() * result_.response * C_)
                                           .completeOrthogonalDecomposition()
                                           .solve(C_.transpose() * left);
    x_target = step.lambda_fixed + prolong(step.directions, Eigen::VectorXd(y0 - Z * shift), m);
    delta_target = delta_ + shift;
    return x_target.allFinite() && delta_target.allFinite();
  }

  // The full step to the target: Newton steps on the active sets of contact are taken whole (a
  // primal-dual active set method), the merit may rise on the way (on a free plate held by friction,
  // by up to twice between two falls, while the contact zone shrinks ring by ring); halving them crept
  // at a few percent per step there. So steps are halved (halve_back) only in a second, damped try.
  void take_full_step(const Eigen::VectorXd& x_target, const Eigen::VectorXd& delta_target) {
    if (settings_.damped) step_start_x_ = x_, step_start_Qx_ = Qx_, step_start_delta_ = delta_;  // for halve_back
    Qx_ += apply(x_target - x_);
    x_ = x_target;
    delta_ = delta_target;
    merit_ = merit(x_, Qx_, delta_);
  }
  // The step just taken, halved back towards where it started until the merit falls below
  // `merit_before` (or kMaxHalvings times): the state moves along the same segment, Qλ with it.
  void halve_back(double merit_before) {
    const Eigen::VectorXd dx = x_ - step_start_x_, dQx = Qx_ - step_start_Qx_, ddelta = delta_ - step_start_delta_;
    double t = 1;
    for (int halving = 0; halving < kMaxHalvings && !(merit_ < merit_before); ++halving) {
      t /= 2;
      x_ = step_start_x_ + t * dx;
      Qx_ = step_start_Qx_ + t * dQx;
      delta_ = step_start_delta_ + t * ddelta;
      merit_ = merit(x_, Qx_, delta_);
    }
  }

  const BoxDiscQP& qp_;
  const Eigen::MatrixXd& G_;
  const Eigen::VectorXd& e_;
  const Eigen::MatrixXd& C_;
  const EqualityNewtonSettings& settings_;
  const double rho_, g_scale_;
  Eigen::VectorXd x_, Qx_, delta_;
  Eigen::VectorXd step_start_x_, step_start_Qx_, step_start_delta_;  // the iterate before the last step
  std::vector<Direction> last_directions_;                           // the active sets of the last step
  std::unordered_set<std::size_t> seen_;                             // fingerprints of every step's active sets
  bool cycled_ = false;   // this step's sets are those of an earlier step but the last
  bool settled_ = false;  // this step's sets are those of the last step
  double merit_ = INFINITY;
  Eigen::VectorXd best_x_, best_delta_;  // the least-merit iterate so far (the start included)
  double best_merit_ = INFINITY;
  EqualityNewtonResult result_;
};

}  // namespace

EqualityNewtonResult solve_equality_newton(const BoxDiscQP& problem, const Eigen::MatrixXd& G, const Eigen::VectorXd& e,
                                           const Eigen::MatrixXd& conditions, const Eigen::VectorXd& start,
                                           const EqualityNewtonSettings& settings) {
  if (problem.matrix_free() || start.size() != problem.size()) return {};
  return JointNewton(problem, G, e, conditions, start, settings).run();
}

}  // namespace contact3d
