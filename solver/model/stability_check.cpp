#include "model/stability_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "base/memory.hpp"
#include "linalg/blas_buffers.hpp"
#include "linalg/dense_cholesky.hpp"
#include "linalg/symmetric_product.hpp"

namespace contact3d {

namespace {

// Above this estimate of cond(Q) the multipliers lose most of their digits to rounding and to the
// QP's stopping tolerance; the paper's brick has 1.5e4, the bodies of results/bodies at most ~1e6.
constexpr double kIllConditionedDual = 1e10;
// Above this, and up to kIllConditionedDual, the QP's stopping test (its projected gradient below rtol =
// 1e-10 of h by default) bounds λ's error only to about cond(Q)·rtol of its size: a steel strip 5 mm thick
// meshed one element through, cond(Q) 5e8, converged with its residuals at 1e-10 and u 6.1e-4 (λ_n 1.1e-3)
// from the independent oracle's answer; with solver.qp_rtol = 1e-12 its gap violation fell 60-fold.
constexpr double kPoorlyConditionedDual = 1e8;

// (5.1) fails: `count` rows of 𝔹 are linearly dependent; the cells of the first few of `rows`.
[[noreturn]] void throw_dependent_rows(const std::vector<int>& rows, int count, const Partition& part, int r) {
  std::string cells;
  for (std::size_t k = 0; k < rows.size() && k < 8; ++k) {
    const int cell = rows[k] % r;
    const auto& c = part.cells[cell];
    cells += "\n  cell " + std::to_string(cell) + " [" + number(c.lo.x()) + ", " + number(c.hi.x()) + "] x [" +
             number(c.lo.y()) + ", " + number(c.hi.y()) + "], area " + number(c.area);
  }
  throw InputError(
      "the multiplier partition violates the stability condition (5.1): " + std::to_string(count) +
      " rows of the contact operator are linearly dependent" +
      (cells.empty() ? std::string(" (no row could be named: check the moduli and units)") : ", e.g." + cells) +
      "\nuse a larger contact.cell_size (H), e.g. twice the current one");
}

// Stability (5.1): 𝔹 has full row rank iff Q = 𝔹K⁻¹𝔹ᵀ is positive definite. Returns an
// estimate of cond(Q) (Lanczos steps on Q, subspace iteration on Q⁻¹) and the Cholesky factor it
// used, which the QP's Newton steps go on solving with (qp/bordered_newton.hpp); when its Cholesky fails or is
// near-singular, a pivoted LDLᵀ names the cells whose rows are dependent (and throws). With `single`
// (the QP's single-precision products are on: large Q) the factor for the subspace iteration is
// first tried in single precision, on `single_copy` (Q = single_scale · single_copy, consumed); it is
// kept only when its pivots stay far above single's rounding (kSinglePivotFloor), so that a nearly
// dependent Q always reaches the double tests.
struct StabilityCheck {
  double condition = 0;
  std::shared_ptr<DualOperatorFactor> factor;  // Q = scale · L Lᵀ (null: the LDLᵀ path, no factor)
};
// Cholesky pivots over Q's diagonal: a pivot is the part of its row's diagonal that the rows before it
// leave over, so the ratio is near 0 exactly where a row nearly depends on them, whatever the cells'
// sizes (graded cells make Q's diagonal itself span orders of magnitude).
Eigen::VectorXd relative_pivots(const Eigen::VectorXd& pivots, const DenseView& Q) {
  Eigen::VectorXd out = pivots;
  for (Eigen::Index k = 0; k < out.size(); ++k) out[k] /= Q(k, k);
  return out;
}

StabilityCheck check_stability(const DenseView& Q, double lambda_max, const Partition& part, int r,
                               Eigen::MatrixXf single_copy, double single_scale) {
  constexpr double kSinglePivotFloor = 1e-4;
  if (single_copy.size() > 0 && lambda_max > 0) {
    auto factor = std::make_shared<DualOperatorFactor>();
    factor->in_single.emplace(std::move(single_copy));
    factor->scale = single_scale;
    if (factor->in_single->ok()) {
      const Eigen::VectorXd d = relative_pivots(factor->in_single->pivots(), Q);
      if (d.minCoeff() > kSinglePivotFloor * d.maxCoeff())
        return {lambda_max / smallest_eigenvalue(*factor->in_single, Q), std::move(factor)};
    }
  }
  {  // the fast path: LAPACK Cholesky (blocked, threaded; far faster than the pivoted LDLᵀ)
    auto factor = std::make_shared<DualOperatorFactor>();
    factor->in_double.emplace(Q);
    if (factor->in_double->ok()) {
      const Eigen::VectorXd d = relative_pivots(factor->in_double->pivots(), Q);
      if (d.minCoeff() > 1e-11 * d.maxCoeff()) {
        // cond(Q) = λmax / λmin: λmax by Lanczos steps on Q (estimate_norm), λmin with the factor.
        return {lambda_max / smallest_eigenvalue(*factor->in_double, Q), std::move(factor)};
      }
    }
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(Q);
  const auto& perm = ldlt.transpositionsP();
  Eigen::VectorXi order = Eigen::VectorXi::LinSpaced(Q.rows(), 0, static_cast<int>(Q.rows()) - 1);
  order = perm * order;  // pivot k of the LDLᵀ sits at row (P·idx)[k] of Q
  Eigen::VectorXd d = ldlt.vectorD();
  for (Eigen::Index k = 0; k < d.size(); ++k) d[k] /= Q(order[k], order[k]);  // relative, as above
  const double dmax = d.cwiseAbs().maxCoeff();
  std::vector<int> bad;
  for (int k = 0; k < d.size(); ++k)
    if (!(d[k] > 1e-11 * dmax)) bad.push_back(k);
  if (bad.empty()) return {dmax / d.minCoeff(), nullptr};
  // Map pivots back through the LDLT permutation to rows of 𝔹.
  std::vector<int> rows;
  for (const int k : bad) rows.push_back(order[k]);
  throw_dependent_rows(rows, static_cast<int>(bad.size()), part, r);
}

// cond(D^{-1/2} Q D^{-1/2}), D = diag Q: the condition of the problem the Jacobi-scaled QP solves,
// by Lanczos steps on it and subspace iteration through the stability check's factor of Q.
double jacobi_scaled_condition(const DenseView& Q, const DualOperatorFactor& factor) {
  const Eigen::VectorXd scale = Q.diagonal().cwiseSqrt().cwiseInverse();
  const double largest = estimate_norm(Q.rows(), [&](const Eigen::VectorXd& x) {
    return Eigen::VectorXd(scale.cwiseProduct(symmetric_product(Q, scale.cwiseProduct(x))));
  });
  const double smallest = factor.in_double ? smallest_eigenvalue(*factor.in_double, Q, scale)
                                           : smallest_eigenvalue(*factor.in_single, Q, scale);
  return smallest > 0 ? largest / smallest : std::numeric_limits<double>::infinity();
}

// "≈ 1.2e+05" (`relation` "≳" for a bound), or what an estimate that came out NaN means (never "-nan").
std::string condition_text(double condition, const std::string& relation = "≈") {
  return std::isnan(condition) ? std::string("not estimated (see the warning)") : relation + " " + number(condition, 3);
}

// Q's entries scale as 1/young: with young = 1e200 Pa they are about 1e-200, and the estimate's
// squares underflow to 0/0 (the run printed "cond(Q) ≈ -nan" and went on). The answer may still be
// right, so this is a warning, with the likely cause.
void warn_if_condition_unknown(double q_size, SolveResult& res) {
  if (!std::isnan(res.stability_condition)) return;
  res.warnings.push_back("cond(Q) could not be estimated: Q's largest entry is " + number(q_size, 3) +
                         ", too near double precision's limits for the estimate's squares (they under- or "
                         "overflow); the scene's material moduli or loads are far from any physical scale, so check "
                         "their units (material.young in Pa with lengths in m)");
}

// Lanczos steps of the matrix-free route's stability check (one product by Q each).
constexpr int kLanczosSteps = 40;

// Stability (5.1) without Q (the matrix-free route): Q = 𝔹K⁻¹𝔹ᵀ is positive definite iff 𝔹 has
// full row rank (checked before this, contact_operator.hpp's dependent_rows). cond(Q) and
// ‖Q‖ by Lanczos steps on Q (one product each): the Ritz values lie inside the spectrum, so the
// condition number is estimated from below.
double check_stability_without_Q(const DualProblem& dual, double& q_norm) {
  const SpectrumEstimate spectrum = lanczos_extremes(
      dual.size(), [&dual](const Eigen::VectorXd& v) { return dual.apply_Q(v); }, kLanczosSteps);
  q_norm = spectrum.largest;
  return spectrum.smallest > 0 ? spectrum.largest / spectrum.smallest : std::numeric_limits<double>::infinity();
}

}  // namespace

// Where the QP solves the Jacobi-scaled problem its condition is what costs digits: cells of very
// different sizes (graded) spread Q's diagonal, which the scaling takes out.
double dual_condition(const SolveResult& res) {
  return res.stability_condition_scaled > 0 ? res.stability_condition_scaled : res.stability_condition;
}

bool dual_ill_conditioned(const SolveResult& res) { return dual_condition(res) > kIllConditionedDual; }

std::shared_ptr<DualOperatorFactor> check_dual_stability(const DualProblem& dual, double& q_norm,
                                                         const ContactOperator& op, const QpSettings& qp,
                                                         double dual_bytes, Progress& report, SolveResult& res) {
  const auto warn_if_ill_conditioned = [&res] {
    if (dual_ill_conditioned(res))
      res.warnings.push_back("the dual operator Q is ill-conditioned (cond(Q) ≈ " + number(res.stability_condition) +
                             ")" +
                             (res.stability_condition_scaled > 0
                                  ? ", Jacobi-scaled as the QP solves it " + number(res.stability_condition_scaled)
                                  : std::string()) +
                             ": λ and the contact pressure may be inaccurate although the residuals are small. Either "
                             "some multiplier cells are nearly dependent (cells smaller than the elements, or a body "
                             "thinner than a cell): use a larger contact.cell_size (H); or the body bends freely "
                             "between its supports and the contact (a slender or soft part): hold it nearer the "
                             "contact, or check λ against a run with a tighter solver.qp_rtol");
    else if (dual_condition(res) > kPoorlyConditionedDual)
      res.warnings.push_back(
          "the dual operator Q is poorly conditioned (cond(Q) ≈ " + number(dual_condition(res), 3) +
          (res.stability_condition_scaled > 0
               ? " Jacobi-scaled as the QP solves it; unscaled " + number(res.stability_condition, 3)
               : std::string()) +
          "): the QP stops where its projected gradient is below a tolerance of the loads (1e-10 for the answer's "
          "solve by default), "
          "which bounds λ and the contact pressure only to about cond(Q) times that, although the residuals are "
          "small (u is usually far closer, and λ often is too); the common causes are a body thin or slender against "
          "the cells (a strip or plate) and cells about as small as the elements under them (where a graded mesh "
          "coarsens under uniform cells), and a finer mesh, through the thickness too, raises cond(Q): use a larger "
          "contact.cell_size (H), or see how far λ moves in a run with --set solver.qp_rtol=1e-12");
  };
  // 𝔹's own rank first, on every route: a Q formed by forward solves through an earlier factor of K
  // (contact.cell_size = "auto"'s second solve) carries their rounding, and a partition whose rows are
  // dependent (a cylinder's small round face, cells of 1.5h: refused on the augmented route) passed its
  // pivot test with cond(Q) ≈ 2.8e20 and took 322 000 products for 48 multipliers.
  if (const std::vector<int> bad = dependent_rows(op.B); !bad.empty())
    throw_dependent_rows(bad, static_cast<int>(bad.size()), res.partition, op.r);
  if (!dual.forms_Q()) {
    res.stability_condition = check_stability_without_Q(dual, q_norm);
    warn_if_ill_conditioned();
    warn_if_condition_unknown(q_norm, res);
    report.stage("stability (5.1): 𝔹 has full row rank; cond(Q) " + condition_text(res.stability_condition, "≳") +
                 " (Lanczos, " + std::to_string(kLanczosSteps) + " products)");
    return nullptr;
  }
  Eigen::MatrixXf single_copy;
  double single_scale = 1;
  if (uses_single_products(qp.precision, dual.size())) {
    single_scale = std::max(dual.Q().diagonal().maxCoeff(), std::numeric_limits<double>::min());  // |Q_ij| <= max Q_kk
    // One column more: the QP's own single copy goes above the factor (SingleCholesky::spare_upper).
    single_copy = lower_triangle_in_single(dual.Q(), single_scale, Eigen::VectorXd(), true);
    q_norm = estimate_norm(&single_copy, single_scale);
  } else {
    q_norm = estimate_norm(dual.Q());
  }
  StabilityCheck check = check_stability(dual.Q(), q_norm, res.partition, op.r, std::move(single_copy), single_scale);
  res.stability_condition = check.condition;
  if (res.stability_condition > kPoorlyConditionedDual && qp.scaling == QpScaling::Jacobi && check.factor)
    res.stability_condition_scaled = jacobi_scaled_condition(dual.Q(), *check.factor);
  warn_if_ill_conditioned();
  warn_if_condition_unknown(dual.Q().diagonal().maxCoeff(), res);
  report.stage("stability (5.1): cond(Q) " + condition_text(res.stability_condition) +
               (res.stability_condition_scaled > 0
                    ? ", Jacobi-scaled (the QP's) ≈ " + number(res.stability_condition_scaled, 3)
                    : std::string()));
  const bool takes_newton_steps = qp.variant == QpVariant::Auto || qp.variant == QpVariant::Ssn;
  if (!check.factor || qp.newton_systems != NewtonSystems::Auto || !takes_newton_steps) return nullptr;
  const double needed = dual_bytes + check.factor->bytes();
  const double available = static_cast<double>(available_memory_bytes());
  if (available > 0 && needed > 0.9 * available) return nullptr;
  return check.factor;
}

}  // namespace contact3d
