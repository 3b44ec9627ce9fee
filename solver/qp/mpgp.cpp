#include "qp/mpgp.hpp"

#include <cmath>
#include <cstdio>

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

std::string qp_heartbeat_line(const char* method, const QpResult& so_far, double rtol, const Progress& progress) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "  qp (%s): iteration %d, %d products, projected gradient %.2e (target %.0e), %.1f s",
                method, so_far.iterations, so_far.hessian_products, so_far.projected_gradient, rtol,
                progress.elapsed());
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

}  // namespace

QpResult solve_mpgp(const BoxDiscQP& qp, Eigen::VectorXd& lambda, const MpgpSettings& settings) {
  QpResult result;
  if (!prepare_start(qp, lambda)) {  // S(λ) = ½λᵀQλ: the minimiser is λ = 0
    result.status = QpStatus::Converged;
    return result;
  }
  const double h_norm = qp.h.norm();
  const double alpha = settings.alpha_scale / qp.q_norm;
  const double tol = settings.rtol * h_norm;
  State s{qp, lambda, {}, {}, result};
  s.refresh_gradient();
  Eigen::VectorXd p = s.split.free;

  for (result.iterations = 0; result.iterations < settings.max_iterations; ++result.iterations) {
    const bool converged = s.meets(tol, p);
    const double free_sq = s.split.free.squaredNorm(), chopped_sq = s.split.chopped.squaredNorm();
    result.projected_gradient = std::sqrt(free_sq + chopped_sq) / h_norm;
    if (!std::isfinite(result.projected_gradient)) {
      result.status = QpStatus::Breakdown;
      return result;
    }
    if (converged) {
      result.status = QpStatus::Converged;
      return result;
    }
    if (settings.progress)
      settings.progress->beat([&] { return qp_heartbeat_line("mpgp", result, settings.rtol, *settings.progress); });

    const Eigen::VectorXd before = lambda;  // g is valid here
    if (chopped_sq <= settings.gamma * settings.gamma * free_sq) {
      // Proportional iterate: conjugate-gradient step on the free set, or expansion.
      const Eigen::VectorXd Qp = s.apply(p);
      const double pQp = p.dot(Qp);
      if (!(pQp > 0)) {
        result.status = QpStatus::Breakdown;
        return result;
      }
      const double a_cg = s.g.dot(p) / pQp;
      const double a_f = max_feasible_step(qp, lambda, p);
      if (a_cg <= a_f) {
        ++result.cg_steps;
        lambda -= a_cg * p;
        s.g -= a_cg * Qp;
        s.resplit();
        const double beta = s.split.free.dot(Qp) / pQp;
        p = s.split.free - beta * p;
        continue;
      }
      ++result.expansion_steps;
      switch (settings.expansion) {
        case ExpansionKind::ProjectedCG:
          lambda -= a_cg * p;
          project(qp, lambda);
          s.move_gradient_from(before);
          break;
        case ExpansionKind::FreeGradient:
        case ExpansionKind::FullGradient: {
          lambda -= a_f * p;
          s.g -= a_f * Qp;
          project(qp, lambda);
          const Eigen::VectorXd on_boundary = lambda;
          lambda -=
              alpha * (settings.expansion == ExpansionKind::FullGradient ? s.g : split_gradient(qp, lambda, s.g).free);
          project(qp, lambda);
          s.move_gradient_from(on_boundary);
          break;
        }
      }
      p = s.split.free;
      continue;
    }
    // Not proportional: proportioning step. Along the chopped gradient with an exact line
    // search when that stays feasible (always on the half-lines); otherwise — and always in
    // the FullGradient variant, the paper's "proportioning and expansion performed
    // simultaneously" — one gradient-projection step of fixed length ᾱ, which decreases S for
    // ᾱ < 2/‖Q‖ (a projected line-search step on the discs can cycle).
    ++result.proportioning_steps;
    bool done = false;
    if (settings.expansion != ExpansionKind::FullGradient) {
      const Eigen::VectorXd d = s.split.chopped;
      const Eigen::VectorXd Qd = s.apply(d);
      const double dQd = d.dot(Qd);
      if (!(dQd > 0)) {
        result.status = QpStatus::Breakdown;
        return result;
      }
      const double a = s.g.dot(d) / dQd;
      const Eigen::VectorXd trial = lambda - a * d;
      if (is_feasible(qp, trial, 0.0)) {  // strict: a tangential step along a circle never is
        lambda = trial;
        s.g -= a * Qd;
        s.resplit();
        done = true;
      }
    }
    if (!done) {
      lambda -= alpha * s.g;
      project(qp, lambda);
      s.move_gradient_from(before);
    }
    p = s.split.free;
  }
  result.status = QpStatus::IterationLimit;
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
  total.coarse_products += part.coarse_products;
}

}  // namespace contact3d
