#include "qp/hybrid_qp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "qp/ssn.hpp"

namespace contact3d {
namespace {

// ‖gᴾ(λ)‖ / ‖h‖ at a feasible λ (one product).
double relative_projected_gradient(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, double h_norm) {
  const GradientSplit split = split_gradient(qp, lambda, qp.apply(lambda) - qp.h);
  return std::sqrt(split.free.squaredNorm() + split.chopped.squaredNorm()) / h_norm;
}

// The stop at the rounding floor, judged at the λ handed back with an exact product: a round that
// ends on its slow steps, and an MPGP window, report the ‖gᴾ‖ from before their last step (a
// window's possibly from a drifted single-precision gradient). True (converged, counted) when λ is
// within kRoundingSlack of the target.
bool stopped_at_the_floor(const BoxDiscQP& qp, const Eigen::VectorXd& lambda, double h_norm, double rtol,
                          QpResult& total) {
  total.projected_gradient = relative_projected_gradient(qp, lambda, h_norm);
  ++total.hessian_products;
  if (!(total.projected_gradient <= RoundingFloor::kRoundingSlack * rtol)) return false;
  total.status = QpStatus::Converged;
  ++total.rounding_stops;
  return true;
}

}  // namespace

bool NewtonRoundGate::admit(double pg) {
  if (rounds_ >= free_rounds_ && !(pg < pg_at_last_round_)) return false;
  ++rounds_;
  pg_at_last_round_ = pg;
  return true;
}

bool RoundingFloor::reached(double pg, double rtol) {
  const bool stalled = pg <= kRoundingSlack * rtol && pg > kRoundGain * best_round_end_;
  best_round_end_ = std::min(best_round_end_, pg);
  return stalled;
}

bool RoundingFloor::reached_by_windows(double pg, double rtol) {
  if (!(pg <= kRoundingSlack * rtol)) {
    stalled_windows_ = 0;
    return false;
  }
  if (pg < kRoundGain * window_anchor_) {  // a real gain: the stall, if any, starts here
    window_anchor_ = pg;
    stalled_windows_ = 0;
    return false;
  }
  if (++stalled_windows_ < kStalledWindows) return false;
  stalled_windows_ = 0;  // judged now (one exact product); judged again after as many windows more
  return true;
}

int default_window(const BoxDiscQP& qp) {
  return qp.matrix_free() ? kMinWindow : std::max(kMinWindow, qp.size() / 256);
}

QpResult solve_hybrid(const BoxDiscQP& qp, Eigen::VectorXd& lambda, const HybridSettings& settings) {
  QpResult total;
  if (!prepare_start(qp, lambda)) {
    total.status = QpStatus::Converged;
    return total;
  }
  const double h_norm = qp.h.norm();
  const int window = settings.window > 0 ? settings.window : default_window(qp);
  double pg_before = relative_projected_gradient(qp, lambda, h_norm);
  ++total.hessian_products;
  NewtonRoundGate newton_rounds(qp.matrix_free() || qp.has_low_rank() ? std::numeric_limits<int>::max()
                                                                      : settings.max_newton_rounds);
  RoundingFloor floor;
  while (total.iterations < settings.max_iterations) {
    MpgpSettings mpgp;
    mpgp.rtol = settings.rtol;
    mpgp.single_products = settings.single_products;
    mpgp.max_iterations = std::min(window, settings.max_iterations - total.iterations);
    mpgp.progress = settings.progress;
    mpgp.earlier = &total;
    add_work(total, solve_mpgp(qp, lambda, mpgp));
    if (total.status != QpStatus::IterationLimit) return total;  // converged, or a breakdown
    if (floor.reached_by_windows(total.projected_gradient, settings.rtol) &&
        stopped_at_the_floor(qp, lambda, h_norm, settings.rtol, total))
      return total;
    const bool mpgp_is_slow = total.projected_gradient > 0.1 * pg_before;
    if (mpgp_is_slow && newton_rounds.admit(total.projected_gradient)) {
      SsnSettings ssn;
      ssn.rtol = settings.rtol;
      ssn.progress = settings.progress;
      ssn.earlier = &total;
      ssn.stop_when_linear = true;
      ssn.fallback_to_mpgp = false;
      ssn.damped_step_budget = window;  // a damped step must not cost more than an MPGP window
      add_work(total, solve_ssn(qp, lambda, ssn));
      if (total.status == QpStatus::Converged) return total;
      if (floor.reached(total.projected_gradient, settings.rtol) &&
          stopped_at_the_floor(qp, lambda, h_norm, settings.rtol, total))
        return total;
    }
    pg_before = total.projected_gradient;
  }
  total.status = QpStatus::IterationLimit;
  return total;
}

}  // namespace contact3d
