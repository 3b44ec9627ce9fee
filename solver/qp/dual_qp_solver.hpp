// DualQpSolver: the dual QP (5.5) of one scene with its solver chosen once — MPGP (the paper's
// algorithm), MPGP with projected-CG expansion, semismooth Newton, or the hybrid of MPGP and
// Newton steps ("auto", the default) — on the Jacobi-scaled or
// the plain problem. Q and h are fixed per scene (h less Gᵀμ where equality constraints are set,
// set_equality); each solve() takes the radii c_i of the disc constraints (which change from one
// fixed-point step to the next) and a warm start.
#pragma once

#include <functional>
#include <memory>
#include <optional>

#include <Eigen/Core>

#include "base/named_enum.hpp"
#include "linalg/dense_cholesky.hpp"
#include "qp/bordered_newton.hpp"
#include "qp/box_disc_qp.hpp"
#include "qp/jacobi_scaling.hpp"
#include "qp/mpgp.hpp"
#include "qp/radius_sensitivity.hpp"

namespace contact3d {

enum class QpVariant { Auto, Mpgp, MpgpProjectedCG, Ssn };
inline constexpr NameTable<QpVariant, 4> kQpVariantNames{{{QpVariant::Auto, "auto"},
                                                          {QpVariant::Mpgp, "mpgp"},
                                                          {QpVariant::MpgpProjectedCG, "mpgp_projcg"},
                                                          {QpVariant::Ssn, "ssn"}}};

enum class QpScaling { None, Jacobi };
inline constexpr NameTable<QpScaling, 2> kQpScalingNames{{{QpScaling::Jacobi, "jacobi"}, {QpScaling::None, "none"}}};

// Products of MPGP's recursive gradient updates: in double, or through a single-precision copy of Q
// with every convergence decision on a gradient computed in double (mpgp.hpp). "auto": mixed from
// kMixedPrecisionMinSize multipliers on, where Q outgrows the caches and its products stream memory.
enum class QpPrecision { Auto, Double, Mixed };
inline constexpr NameTable<QpPrecision, 3> kQpPrecisionNames{
    {{QpPrecision::Auto, "auto"}, {QpPrecision::Double, "double"}, {QpPrecision::Mixed, "mixed"}}};
inline constexpr int kMixedPrecisionMinSize = 2000;
bool uses_single_products(QpPrecision precision, int multipliers);

// How Newton steps solve their reduced systems (newton_system.hpp): "auto" through the factor of the
// whole Q that the stability check (5.1) made, bordered by the fixed and sliding directions
// (bordered_newton.hpp), wherever that costs fewer flops than factoring the reduced matrix, which
// is done otherwise; "reduced": always a factorization of the reduced matrix.
enum class NewtonSystems { Auto, Reduced };
inline constexpr NameTable<NewtonSystems, 2> kNewtonSystemsNames{
    {{NewtonSystems::Auto, "auto"}, {NewtonSystems::Reduced, "reduced"}}};

// The fine level of the matrix-free Newton steps' CG (reduced_cg.hpp): FETI's lumped preconditioner
// from 𝔹K𝔹ᵀ (lumped_preconditioner.hpp), or the reduced system's diagonal.
enum class CgPreconditioner { Lumped, Diagonal };
inline constexpr NameTable<CgPreconditioner, 2> kCgPreconditionerNames{
    {{CgPreconditioner::Lumped, "lumped"}, {CgPreconditioner::Diagonal, "diagonal"}}};

struct QpSettings {
  QpVariant variant = QpVariant::Auto;  // MPGP, switching to Newton steps where it is slow (hybrid_qp.hpp)
  QpScaling scaling = QpScaling::Jacobi;
  QpPrecision precision = QpPrecision::Auto;
  int max_iterations = 100000;
  NewtonSystems newton_systems = NewtonSystems::Auto;
  CgPreconditioner cg_preconditioner = CgPreconditioner::Lumped;  // matrix-free route only (the model builds it)
};

// Q seen only through products (a matrix-free dual, linalg/dual_problem.hpp): what the QP needs of it.
struct MatrixFreeQ {
  std::function<Eigen::VectorXd(const Eigen::VectorXd&)> product;
  std::function<Eigen::MatrixXd(const Eigen::MatrixXd&)> block_product;  // optional: several columns at once
  Eigen::VectorXd diagonal;
  std::vector<int> coarse_group;                  // optional: BoxDiscQP::coarse_group (of the multipliers)
  std::shared_ptr<const LumpedOperators> lumped;  // optional: BoxDiscQP::lumped
  // Optional: Q v in single precision (BoxDiscQP::single_product) where QpSettings::precision asks
  // for single products: MPGP's recursive gradient updates, the Newton steps' CG where its tolerance
  // allows (reduced_cg.hpp), and the two-level preconditioner's coarse products.
  std::function<Eigen::VectorXd(const Eigen::VectorXd&)> single_product;
  std::function<Eigen::MatrixXd(const Eigen::MatrixXd&)> single_block_product;  // optional, several columns
};

class DualQpSolver {
 public:
  // `Q` must outlive the solver; `q_norm` is an estimate of ‖Q‖ (estimate_norm).
  // `factor`: a Cholesky factor of Q for the Newton steps (QpSettings::newton_systems; null: none).
  DualQpSolver(const DenseView& Q, const Eigen::VectorXd& h, int r, bool with_friction, double q_norm,
               const QpSettings& settings, std::shared_ptr<DualOperatorFactor> factor = nullptr);
  // Matrix-free: Q only through products and its diagonal (MatrixFreeQ), through its single products
  // where it has them and `settings.precision` asks for them (MatrixFreeQ::single_product says where),
  // else in double; Newton steps ("auto", "ssn") inexact by CG (qp/reduced_cg.hpp), the sensitivity
  // by CG too.
  DualQpSolver(MatrixFreeQ Q, const Eigen::VectorXd& h, int r, bool with_friction, double q_norm,
               const QpSettings& settings);
  // Solves for the radii `radius` (size r; ignored when frictionless) to ‖gᴾ‖ <= rtol ‖h‖,
  // from the warm start `lambda` (in the original, unscaled variables; of another size: from zero),
  // which holds the result.
  QpResult solve(const Eigen::VectorXd& radius, Eigen::VectorXd& lambda, double rtol);

  // Equality constraints Gλ = e (G: k × m, k <= 6): the equilibrium of the rigid motions that only
  // the contact holds (model/held_by_contact.hpp), FETI's "Gλ = e". From then on solve() also finds
  // their multiplier μ: λ(μ) solves the QP with the linear term h − Gᵀμ, and μ is the root of
  // F(μ) = Gλ(μ) − e, piecewise affine and monotone, found by Newton steps with a Jacobian from the
  // reduced system of λ's active sets (difference quotients where it cannot be solved; kept from
  // solve to solve, Broyden-updated, measured again when a step fails, when a full step cut ‖F‖ less
  // than tenfold (the active sets moved under Broyden's secant) or when the reachable rows change:
  // rows no multiplier can move under these radii, a slide without friction, are left to the caller
  // in equality_residual(), and the conditions kept are the motions whose work on the multipliers
  // left out is orthogonal to theirs, so the answer does not depend on the motions' basis) and
  // halving; where no halving lowers ‖F‖ but the step overshoots the maximum of the concave dual φ
  // (F = ∇φ) along it, that maximum is searched for (false position on Fᵀs) and taken; along motions
  // no contact force responds to yet (a body above its gaps) μ jumps to the next touch, or to φ's
  // maximum along the jump where it lies before; to ‖F‖ <= max(rtol, 1e-9)·‖e‖ (‖e‖ at least
  // 1e-4·‖G‖‖λ‖; 1e-7 where the inner solves' rounding stops the descent even at their tightest),
  // the inner solves to min(rtol/100, 1e-8), tightened where the descent stops. Where these steps
  // leave the loads unbalanced, the augmented Lagrangian takes over from their best iterate
  // (solve_with_augmented_lagrangian). μ is warm-started too. On a dense Q with Newton steps in the QP
  // ("auto", "ssn"), semismooth Newton steps on λ and μ together (equality_newton.hpp) go first,
  // from the first inner solve; the steps on μ alone only where they do not converge.
  void set_equality(Eigen::MatrixXd G, Eigen::VectorXd e);
  bool has_equality() const { return G_.rows() > 0; }
  // Whether the Newton steps' solver through the factor of Q switched from single to double
  // (bordered_newton.hpp: its refinements stalled).
  bool newton_factor_switched_to_double() const { return bordered_ && bordered_->switched_to_double(); }
  const Eigen::VectorXd& equality_multiplier() const { return mu_; }  // μ of the last solve
  // ‖Gλ − e‖ of the last solve over max(‖e‖, 1e-4·‖G‖‖λ‖): the loads along the motions, or where they are
  // only rounding (a symmetric body's slide) the contact forces' size along them.
  double equality_residual() const { return equality_residual_; }
  // dλ/dc at `lambda`, the solution of the last solve(), in the original variables, computed on the
  // problem that solve() solved (Jacobi-scaled or not; through the factor of Q where the Newton steps
  // go through it; by CG on a matrix-free Q). It holds the radii of this solve and must not outlive
  // the solver.
  RadiusSensitivity radius_sensitivity(const Eigen::VectorXd& lambda);
  // Heartbeat lines of long solves go to `progress` (must outlive the solver; null: none).
  void report_progress_to(Progress* progress) { progress_ = progress; }

 private:
  // The problem the solvers work on for the current radii: Jacobi-scaled or not, with the single
  // copy of Q and the bordered Newton solver attached.
  BoxDiscQP solved_problem();
  // `penalty` A (k × m, in the solved problem's variables): ½‖A x‖² is added to the objective.
  // `of_equalities`: an inner solve of the equality loop, in double below kSingleTightestInnerRtol.
  QpResult solve_for_linear_term(const Eigen::VectorXd& radius, Eigen::VectorXd& lambda, double rtol,
                                 const Eigen::MatrixXd* penalty = nullptr, bool of_equalities = false);
  // The equalities by the augmented Lagrangian (the method of multipliers), from mu_ and `lambda`, to
  // ‖P(Gλ − e)‖ <= target within `budget` products: the fallback where the Newton steps on μ do not
  // balance the loads.
  QpResult solve_with_augmented_lagrangian(const Eigen::VectorXd& radius, Eigen::VectorXd& lambda, double rtol,
                                           const Eigen::MatrixXd& P, double target, long budget);
  // solve() with the equality constraints (set_equality): the steps on μ, one EqualitySolve per call.
  class EqualitySolve;
  QpResult solve_with_equality(const Eigen::VectorXd& radius, Eigen::VectorXd& lambda, double rtol);
  void set_linear_term(const Eigen::VectorXd& h);
  Eigen::MatrixXd reachable_columns(const Eigen::VectorXd& radius) const;  // G where λ can be nonzero

  BoxDiscQP qp_;
  std::optional<JacobiScaledQP> jacobi_;
  // The solved (scaled) Q / single_scale_ in single precision (null: double products): above the
  // factor of Q where it has room (SingleCholesky::spare_upper), else the lower triangle of q_single_.
  SingleSymmetric single_;
  Eigen::MatrixXf q_single_;
  std::shared_ptr<const DualOperatorFactor> single_holder_;  // the factor whose array holds single_
  double single_scale_ = 1;
  std::unique_ptr<BorderedNewton> bordered_;  // the Newton steps' route through the factor of Q (or none)
  QpSettings settings_;
  Progress* progress_ = nullptr;
  Eigen::VectorXd h_;                // the linear term of the problem as given (before any −Gᵀμ)
  Eigen::MatrixXd G_;                // equality constraints (0 rows: none)
  Eigen::VectorXd e_, mu_;           // their right-hand side and multiplier
  Eigen::MatrixXd jacobian_;         // dF/dμ as last measured and updated (empty: not yet)
  Eigen::MatrixXd reach_projector_;  // onto the balance conditions of the last solve (P = C Cᵀ)
  double equality_residual_ = 0;
};

}  // namespace contact3d
