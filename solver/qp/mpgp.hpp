// MPGP: Kučera's algorithm for (5.5) — conjugate gradients on the free set combined with
// gradient projection onto the half-lines and discs, proportioning steps that release
// active constraints, and expansion steps that add them (Kučera 2008, ref. [10] of the paper;
// the paper performs proportioning and expansion "simultaneously"). Stops when the projected
// gradient satisfies ‖gᴾ(λ)‖ <= rtol ‖h‖ (the paper's criterion).
// With single-precision products (BoxDiscQP::Q_single or ::single_product) every product goes through it and g is
// updated recursively; g = Qλ − h is recomputed in double every kSingleRefreshEvery updates after a
// projection, and by the stopping test before it accepts: a solve ends only when the exact ‖gᴾ‖
// meets the tolerance. After kSingleFalseStops stops that the exact gradient refuses (the rounding
// of the single products then sits at the tolerance), the solve continues in double.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "base/progress.hpp"

#include "qp/box_disc_qp.hpp"

namespace contact3d {

enum class QpStatus { Converged, IterationLimit, Breakdown };
std::string to_string(QpStatus s);

// How an expansion step leaves the boundary it has just reached.
enum class ExpansionKind {
  FreeGradient,  // λ ← P(λ − ᾱ φ(λ)): MPRGP's fixed-step expansion
  FullGradient,  // λ ← P(λ − ᾱ g(λ)): proportioning and expansion in one step (the paper's reading)
  ProjectedCG,   // λ ← P(λ − a_cg p): project the full conjugate-gradient step
};

inline constexpr int kSingleFalseStops = 2;
inline constexpr int kSingleRefreshEvery = 50;

struct QpResult;

struct MpgpSettings {
  double rtol = 1e-6;  // ‖gᴾ‖ <= rtol ‖h‖
  int max_iterations = 100000;
  double gamma = 1.0;        // proportioning parameter Γ
  double alpha_scale = 1.8;  // ᾱ = alpha_scale / ‖Q‖ (must be < 2)
  ExpansionKind expansion = ExpansionKind::FullGradient;
  Progress* progress = nullptr;  // heartbeat: iterations and ‖gᴾ‖/‖h‖ every few seconds (none: silent)
  // The same QP's work before this call (the hybrid's earlier windows and Newton rounds): counted in the
  // heartbeat, which otherwise restarted at "iteration 0, 1 products" 13 s into a solve.
  const QpResult* earlier = nullptr;
  // Products through the problem's single-precision copy where it has one (false: all in double; the
  // equality loop's tight inner solves, dual_qp_solver.cpp).
  bool single_products = true;
};

struct QpResult {
  QpStatus status = QpStatus::Breakdown;
  int iterations = 0;
  int hessian_products = 0;  // products Q·v — each one is a K⁻¹ application in the paper's count
  int single_products = 0;   // of which through the single-precision copy of Q
  int cg_steps = 0, expansion_steps = 0, proportioning_steps = 0;
  int newton_steps = 0;           // semismooth Newton steps (ssn.hpp, hybrid_qp.hpp; none in MPGP)
  int bordered_steps = 0;         // of which solved through the factor of Q (bordered_newton.hpp)
  int feasible_steps = 0;         // of which feasible descent steps (ssn.hpp)
  int coarse_products = 0;        // of the products, columns of blocked solves for the two-level CG (reduced_cg.hpp)
  double projected_gradient = 0;  // final ‖gᴾ‖ / ‖h‖
  int rounding_stops = 0;         // solves stopped at their rounding floor, a little above rtol (hybrid_qp.hpp)
};

// For a solve made of several: adds `part`'s counts to `total` and takes its status and final gradient.
void add_work(QpResult& total, const QpResult& part);
// `part`'s counts added to `total`, whose status and final gradient stay.
void add_counts(QpResult& total, const QpResult& part);

// The heartbeat line of an inner QP solve: "qp (mpgp): iteration 1200, ‖gᴾ‖/‖h‖ = 3.2e-04 → 1e-06, 4.1 s".
std::string qp_heartbeat_line(const char* method, const QpResult& so_far, double rtol, const Progress& progress,
                              const QpResult* earlier = nullptr);

// Solves from the warm start `lambda` (projected first); on return `lambda` holds the result.
QpResult solve_mpgp(const BoxDiscQP& qp, Eigen::VectorXd& lambda, const MpgpSettings& settings);

}  // namespace contact3d
