#include "qp/mpgp.hpp"

#include <cmath>
#include <cstdio>
#include <optional>

namespace contact3d {

std::string to_string(QpStatus s) {
  switch (s) {
    case QpStatus::Converged:
      return "converged";
    case QpStatus::IterationLimit:
      return "iteration_limit";
    case QpStatus::Breakdown:
      return "breakdown";
  }
  return "?";
}

std::string qp_heartbeat_line(const char* method, const QpResult& so_far, double rtol, const Progress& progress,
                              const QpResult* earlier) {
  const int iterations = so_far.iterations + (earlier ? earlier->iterations : 0);
  const int products = so_far.hessian_products + (earlier ? earlier->hessian_products : 0);
  char buf[160];
  std::snprintf(buf, sizeof buf, "  qp (%s): iteration %d, %d products, projected gradient %.2e (target %.0e), %.1f s",
                method, iterations, products, so_far.projected_gradient, rtol, progress.elapsed());
  return buf;
}

namespace {

// Gradient bookkeeping shared by the step kinds: g = Qλ − h and its split. `single`: products of
// the recursive updates go through Q's single-precision copy; `drifted`: g carries their rounding.
struct State {
  const BoxDiscQP& qp;
  Eigen::VectorXd& lambda;
  Eigen::VectorXd g;
  GradientSplit split;
  QpResult& result;
  bool single = qp.has_single_products();
  bool drifted = false;
  int false_stops = 0, single_updates = 0;

  void refresh_gradient() {
    g = qp.apply(lambda) - qp.h;
    ++result.hessian_products;
    split = split_gradient(qp, lambda, g);
    drifted = false;
    single_updates = 0;
  }
  // g at λ from g at `before`: g += Q (λ − before) through the single copy (a product of the same
  // cost as any other: mixing double products in would evict the single copy from the caches), and
  // afresh in double every kSingleRefreshEvery such updates and whenever products are in double.
  void move_gradient_from(const Eigen::VectorXd& before) {
    if (!single || ++single_updates >= kSingleRefreshEvery) {
      refresh_gradient();
      return;
    }
    g += apply(lambda - before);
    split = split_gradient(qp, lambda, g);
  }
  void resplit() { split = split_gradient(qp, lambda, g); }
  Eigen::VectorXd apply(const Eigen::VectorXd& v) {
    ++result.hessian_products;
    if (!single) return qp.apply(v);
    ++result.single_products;
    drifted = true;
    return qp.apply_single(v);
  }
  double projected_gradient_norm() const { return std::sqrt(split.free.squaredNorm() + split.chopped.squaredNorm()); }
  // The stopping test on an exact gradient: a drifted g that meets `tol` is recomputed first; a
  // refusal restarts the conjugate directions (`p`), and kSingleFalseStops of them end single products.
  bool meets(double tol, Eigen::VectorXd& p) {
    if (projected_gradient_norm() > tol) return false;
    if (!drifted) return true;
    refresh_gradient();
    if (projected_gradient_norm() <= tol) return true;
    if (++false_stops >= kSingleFalseStops) single = false;
    p = split.free;
    return false;
  }
};

// One MPGP solve: each iteration is a stopping test, then one step of the paper's three kinds — a
// conjugate-gradient step on the free set, an expansion where that step would leave the feasible
// set, or a proportioning step where the chopped gradient dominates the free one.
class Mpgp {
 public:
  Mpgp(const BoxDiscQP& qp, Eigen::VectorXd& lambda, const MpgpSettings& settings, QpResult& result)
      : qp_(qp),
        lambda_(lambda),
        settings_(settings),
        result_(result),
        h_norm_(qp.h.norm()),
        alpha_(settings.alpha_scale / qp.q_norm),
        tol_(settings.rtol * h_norm_),
        s_{qp, lambda, {}, {}, result} {
    s_.single = s_.single && settings.single_products;
    s_.refresh_gradient();
    p_ = s_.split.free;
  }

  QpStatus run() {
    for (result_.iterations = 0; result_.iterations < settings_.max_iterations; ++result_.iterations) {
      if (const std::optional<QpStatus> stop = stopping_test()) return *stop;
      if (settings_.progress)
        settings_.progress->beat(
            [&] { return qp_heartbeat_line("mpgp", result_, settings_.rtol, *settings_.progress, settings_.earlier); });
      const Eigen::VectorXd before = lambda_;  // g is valid here
      const bool proportional = chopped_sq_ <= settings_.gamma * settings_.gamma * free_sq_;
      if (!(proportional ? conjugate_gradient_or_expansion(before) : proportioning(before))) return QpStatus::Breakdown;
    }
    return QpStatus::IterationLimit;
  }

 private:
  // Converged on an exact gradient, broken down on a non-finite one, or nothing: go on.
  std::optional<QpStatus> stopping_test() {
    const bool converged = s_.meets(tol_, p_);
    free_sq_ = s_.split.free.squaredNorm();
    chopped_sq_ = s_.split.chopped.squaredNorm();
    result_.projected_gradient = std::sqrt(free_sq_ + chopped_sq_) / h_norm_;
    if (!std::isfinite(result_.projected_gradient)) return QpStatus::Breakdown;
    if (converged) return QpStatus::Converged;
    return std::nullopt;
  }

  // A proportional iterate: the conjugate-gradient step along p where it stays feasible, else an
  // expansion. False on a breakdown (pᵀQp ≤ 0).
  bool conjugate_gradient_or_expansion(const Eigen::VectorXd& before) {
    const Eigen::VectorXd Qp = s_.apply(p_);
    const double pQp = p_.dot(Qp);
    if (!(pQp > 0)) return false;
    const double a_cg = s_.g.dot(p_) / pQp;
    const double a_f = max_feasible_step(qp_, lambda_, p_);
    if (a_cg > a_f) {
      expand(a_cg, a_f, Qp, before);
      return true;
    }
    ++result_.cg_steps;
    lambda_ -= a_cg * p_;
    s_.g -= a_cg * Qp;
    s_.resplit();
    const double beta = s_.split.free.dot(Qp) / pQp;
    p_ = s_.split.free - beta * p_;
    return true;
  }

  // The expansion of settings.expansion: to the boundary along p, then a projected step of fixed
  // length ᾱ (or the projected full conjugate-gradient step); conjugate directions restart.
  void expand(double a_cg, double a_f, const Eigen::VectorXd& Qp, const Eigen::VectorXd& before) {
    ++result_.expansion_steps;
    if (settings_.expansion == ExpansionKind::ProjectedCG) {
      lambda_ -= a_cg * p_;
      project(qp_, lambda_);
      s_.move_gradient_from(before);
    } else {
      lambda_ -= a_f * p_;
      s_.g -= a_f * Qp;
      project(qp_, lambda_);
      const Eigen::VectorXd on_boundary = lambda_;
      lambda_ -= alpha_ *
                 (settings_.expansion == ExpansionKind::FullGradient ? s_.g : split_gradient(qp_, lambda_, s_.g).free);
      project(qp_, lambda_);
      s_.move_gradient_from(on_boundary);
    }
    p_ = s_.split.free;
  }

  // Not proportional: along the chopped gradient with an exact line search when that stays
  // feasible (always on the half-lines); otherwise — and always in the FullGradient variant, the
  // paper's "proportioning and expansion performed simultaneously" — one gradient-projection step
  // of fixed length ᾱ, which decreases S for ᾱ < 2/‖Q‖ (a projected line-search step on the discs
  // can cycle). False on a breakdown (dᵀQd ≤ 0).
  bool proportioning(const Eigen::VectorXd& before) {
    ++result_.proportioning_steps;
    bool moved = false;
    if (settings_.expansion != ExpansionKind::FullGradient && !line_search_along_chopped(moved)) return false;
    if (!moved) {
      lambda_ -= alpha_ * s_.g;
      project(qp_, lambda_);
      s_.move_gradient_from(before);
    }
    p_ = s_.split.free;
    return true;
  }

  // The exact minimiser along the chopped gradient, taken (`moved`) only where it is feasible
  // (strictly: a tangential step along a circle never is). False on a breakdown.
  bool line_search_along_chopped(bool& moved) {
    const Eigen::VectorXd d = s_.split.chopped;
    const Eigen::VectorXd Qd = s_.apply(d);
    const double dQd = d.dot(Qd);
    if (!(dQd > 0)) return false;
    const double a = s_.g.dot(d) / dQd;
    const Eigen::VectorXd trial = lambda_ - a * d;
    if (!is_feasible(qp_, trial, 0.0)) return true;
    lambda_ = trial;
    s_.g -= a * Qd;
    s_.resplit();
    moved = true;
    return true;
  }

  const BoxDiscQP& qp_;
  Eigen::VectorXd& lambda_;
  const MpgpSettings& settings_;
  QpResult& result_;
  const double h_norm_, alpha_, tol_;
  State s_;
  Eigen::VectorXd p_;                    // the conjugate direction on the free set
  double free_sq_ = 0, chopped_sq_ = 0;  // ‖φ‖², ‖β‖² of the last stopping test
};

}  // namespace

QpResult solve_mpgp(const BoxDiscQP& qp, Eigen::VectorXd& lambda, const MpgpSettings& settings) {
  QpResult result;
  if (!prepare_start(qp, lambda)) {  // S(λ) = ½λᵀQλ: the minimiser is λ = 0
    result.status = QpStatus::Converged;
    return result;
  }
  result.status = Mpgp(qp, lambda, settings, result).run();
  return result;
}

void add_work(QpResult& total, const QpResult& part) {
  add_counts(total, part);
  total.status = part.status;
  total.projected_gradient = part.projected_gradient;
}

void add_counts(QpResult& total, const QpResult& part) {
  total.iterations += part.iterations;
  total.hessian_products += part.hessian_products;
  total.single_products += part.single_products;
  total.cg_steps += part.cg_steps;
  total.expansion_steps += part.expansion_steps;
  total.proportioning_steps += part.proportioning_steps;
  total.newton_steps += part.newton_steps;
  total.bordered_steps += part.bordered_steps;
  total.feasible_steps += part.feasible_steps;
  total.coarse_products += part.coarse_products;
  total.rounding_stops += part.rounding_stops;
}

}  // namespace contact3d
