// The method of successive approximations (5.7) for the solution-dependent coefficient:
// φ⁰ = 0; step k solves the Tresca problem with radii c(φᵏ⁻¹) and returns the nodal slip
// G(φᵏ⁻¹) = ‖w_t‖ at the contact nodes. err(k) = ‖G(φᵏ⁻¹) − φᵏ⁻¹‖ / ‖G(φᵏ⁻¹)‖, which for the
// plain iteration φᵏ = G(φᵏ⁻¹) is the paper's ‖φᵏ − φᵏ⁻¹‖ / ‖φᵏ‖. The Anderson variant mixes the
// last few iterates (safeguarded: non-negative slip, restart when err grows).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace contact3d {

enum class FixedPointStatus { Converged, IterationLimit, Stagnation, InnerSolverFailed };
std::string to_string(FixedPointStatus s);

struct FixedPointSettings {
  double tol = 1e-4;
  int max_iterations = 50;
  bool anderson = false;
  int anderson_depth = 5;
  int stagnation_window = 8;  // stop when err has not reached a new minimum for this many steps
  // Inexact early steps: QP tolerance max(qp_rtol, min(1e-3, 1e-2·err(k−1))); a step that meets
  // `tol` with a looser QP tolerance is repeated exactly before declaring convergence.
  bool inexact = false;
};

// One evaluation of G: what the Tresca solve reports back.
struct SlipEvaluation {
  Eigen::VectorXd slip;       // G(φ) at the contact nodes
  bool ok = true;             // false when the inner QP failed
  int qp_iterations = 0;
  int hessian_products = 0;
};

struct FixedPointStep {
  int k = 0;
  double err = 0;
  int qp_iterations = 0;
  int n_mult = 0;             // cumulative multiplications by K⁻¹ (paper's count)
  double seconds = 0;         // wall time of this step
};

struct FixedPointResult {
  FixedPointStatus status = FixedPointStatus::IterationLimit;
  std::vector<FixedPointStep> history;
  Eigen::VectorXd phi;        // the last input φ (the final Tresca solve used c(phi))
  int iterations() const { return static_cast<int>(history.size()); }
};

using SlipMap = std::function<SlipEvaluation(const Eigen::VectorXd& phi, double suggested_qp_rtol)>;
using StepObserver = std::function<void(const FixedPointStep&)>;

// `qp_rtol` is passed on to G unchanged (exact steps, as in the paper) unless settings.inexact.
FixedPointResult solve_fixed_point(const SlipMap& G, int n_phi, const FixedPointSettings& settings, double qp_rtol,
                                   const StepObserver& observe = {});

}  // namespace contact3d
