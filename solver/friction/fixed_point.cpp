#include "friction/fixed_point.hpp"

#include <chrono>
#include <cmath>
#include <algorithm>
#include <deque>

#include <Eigen/Dense>

namespace contact3d {

std::string to_string(FixedPointStatus s) {
  switch (s) {
    case FixedPointStatus::Converged: return "converged";
    case FixedPointStatus::IterationLimit: return "iteration_limit";
    case FixedPointStatus::Stagnation: return "stagnation";
    case FixedPointStatus::InnerSolverFailed: return "inner_solver_failed";
  }
  return "?";
}

namespace {

double relative_change(const Eigen::VectorXd& next, const Eigen::VectorXd& prev) {
  const double denom = next.norm();
  const double diff = (next - prev).norm();
  if (denom == 0) return diff == 0 ? 0.0 : 1.0;
  return diff / denom;
}

// Anderson mixing (type II) over the last pairs (x_j, G(x_j)).
class AndersonMixer {
 public:
  explicit AndersonMixer(int depth) : depth_(depth) {}
  void reset() { xs_.clear(); gs_.clear(); }
  Eigen::VectorXd next(const Eigen::VectorXd& x, const Eigen::VectorXd& gx) {
    xs_.push_back(x);
    gs_.push_back(gx);
    if (static_cast<int>(xs_.size()) > depth_ + 1) { xs_.pop_front(); gs_.pop_front(); }
    const int m = static_cast<int>(xs_.size()) - 1;
    if (m == 0) return gx;
    const Eigen::VectorXd f = gx - x;
    Eigen::MatrixXd dF(x.size(), m), dG(x.size(), m);
    for (int j = 0; j < m; ++j) {
      dF.col(j) = (gs_[j + 1] - xs_[j + 1]) - (gs_[j] - xs_[j]);
      dG.col(j) = gs_[j + 1] - gs_[j];
    }
    const Eigen::VectorXd gamma = dF.colPivHouseholderQr().solve(f);
    if (!gamma.allFinite()) { reset(); return gx; }
    return (gx - dG * gamma).cwiseMax(0.0);  // slips are norms: keep them non-negative
  }

 private:
  int depth_;
  std::deque<Eigen::VectorXd> xs_, gs_;
};

}  // namespace

FixedPointResult solve_fixed_point(const SlipMap& G, int n_phi, const FixedPointSettings& settings, double qp_rtol,
                                   const StepObserver& observe) {
  FixedPointResult result;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n_phi);
  AndersonMixer mixer(settings.anderson_depth);
  int n_mult = 0;
  double best_err = INFINITY;
  int best_k = 0;
  bool force_exact = false;  // an inexact step met tol: repeat it with the exact QP tolerance
  for (int k = 1; k <= settings.max_iterations; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    double rtol_k = qp_rtol;
    if (settings.inexact && k > 1) rtol_k = std::max(qp_rtol, std::min(1e-3, 1e-2 * result.history[k - 2].err));
    if (settings.inexact && k == 1) rtol_k = std::max(qp_rtol, 1e-3);
    if (force_exact) rtol_k = qp_rtol;
    const SlipEvaluation eval = G(x, rtol_k);
    n_mult += eval.hessian_products;
    FixedPointStep step;
    step.k = k;
    step.err = relative_change(eval.slip, x);
    step.qp_iterations = eval.qp_iterations;
    step.n_mult = n_mult;
    step.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    result.history.push_back(step);
    result.phi = x;
    if (observe) observe(step);
    if (!eval.ok) { result.status = FixedPointStatus::InnerSolverFailed; return result; }
    if (step.err <= settings.tol) {
      if (rtol_k <= qp_rtol) { result.status = FixedPointStatus::Converged; return result; }
      force_exact = true;  // same φ again (x unchanged), now with the exact QP tolerance
      continue;
    }
    if (step.err < best_err) { best_err = step.err; best_k = k; }
    else if (k - best_k >= settings.stagnation_window) { result.status = FixedPointStatus::Stagnation; return result; }
    if (settings.anderson) {
      if (k > 1 && step.err > 2 * result.history[k - 2].err) mixer.reset();  // safeguard
      x = mixer.next(x, eval.slip);
    } else {
      x = eval.slip;
    }
  }
  result.status = FixedPointStatus::IterationLimit;
  return result;
}

}  // namespace contact3d
