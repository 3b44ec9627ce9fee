// Which way the dual problem (5.5) is formed once the scene's size is known: the dense Q of the
// scene's solver.schur where Q and its working copies fit in the memory this process can get, else,
// for "auto" in the serial build, the matrix-free route (DualMethod::MatrixFree: the factor of K, no
// m × m array, each product through the factor). The caller measures the memory and says what it chose.
#pragma once

#include <optional>

#include "linalg/dual_problem.hpp"
#include "qp/dual_qp_solver.hpp"

namespace contact3d {

// Bytes per entry of Q that the dense dual solve holds at most: Q and a Newton step's reduced matrix (up
// to m² in double), plus the single-precision copy when it is used (the Jacobi scaling is applied in each
// product, not stored; the stability check's factor, kept for the Newton steps when it fits, is counted
// by check_dual_stability, model/stability_check.hpp).
double dense_dual_bytes_per_entry(const QpSettings& qp, int rows);

// A factor needs kFactorOverhead times its values (CHOLMOD's indices and workspace); a run whose need
// comes within kTightMemory of what the process can get is warned (the system may kill it without a
// message), beyond it refused (contact_solver.cpp, require_factor_fits).
inline constexpr double kFactorOverhead = 1.2;
inline constexpr double kTightMemory = 0.85;

// "auto" on the augmented factor, whose factor holds Q's dense block too (the multipliers ordered last:
// m(m + 1)/2 of its `augmented_lnz` entries), with the dense Q's working copies (`dense_bytes`) on top: true
// where that whole need passes kTightMemory of `available` while the matrix-free route's (the factor of K
// alone, without Q's block) does not — a face of 27 648 multipliers on a slab was sent to the augmented
// factor with 22.1 of 22.3 GiB needed and a warning, where matrix-free needed 2.3 GiB. Where neither fits,
// false: the augmented route's refusal says what it needs.
bool augmented_crowds_memory(double augmented_lnz, int rows, double dense_bytes, double available);
// Beyond this share of the memory for the dense Q alone, "auto" predicts the augmented factor (one more
// symbolic analysis) before choosing it; below it the factor and Q leave room on any body measured.
inline constexpr double kPredictAugmentedShare = 0.2;

// `requested`: solver.schur as the scene states it; `resolved`: what "auto" became for the build
// (augmented; mumps in the distributed build). nullopt: the dense Q does not fit and nothing else
// may be taken (a dense method the scene named, or MUMPS, whose Schur complement is dense).
std::optional<DualMethod> dual_method_for_memory(DualMethod requested, DualMethod resolved, bool dense_Q_fits);

// The matrix-free route's two-level preconditioner (qp/reduced_cg.hpp) for `groups` coarse vectors:
// D·Z and Q·D·Z kept between Newton steps, and Y = A·Z with a blocked product's right-hand sides in a
// step, about 4 · m · groups doubles (176 MiB at 30 000 multipliers and 192 groups). It is taken where
// that is at most kCoarseSpaceShare of the memory available (0: unknown, taken); else the Newton
// steps' CG goes with the diagonal alone.
inline constexpr double kCoarseSpaceShare = 0.25;
double coarse_space_bytes(int multipliers, int groups);
bool coarse_space_fits(int multipliers, int groups, double available_bytes);

// The matrix-free route's lumped preconditioner (qp/lumped_preconditioner.hpp) keeps 𝔹𝔹ᵀ and 𝔹K𝔹ᵀ,
// sparse m × m (about 200 entries a row on the thin slab), where they take at most kLumpedShare of the
// memory available (0: unknown, taken); else the Newton steps' CG goes with the diagonal as fine level.
inline constexpr double kLumpedShare = 0.125;
bool lumped_operators_fit(double bytes, double available_bytes);

// The matrix-free route's single-precision copy of K's factor for the QP's single products
// (linalg/single_precision_factor.hpp, 4 bytes per entry of L) may take at most kSingleFactorShare
// of the memory available: the budget passed to DualProblem::prepare_single_products (0 available:
// unknown, no limit).
inline constexpr double kSingleFactorShare = 0.25;
double single_factor_budget(double available_bytes);

// contact.cell_size = "auto" solving again with cells of 1.5h keeps K, and so its factor: the second
// solve's Q can come from the first solve's augmented factor by forward solves of its 𝔹
// (make_dual_problem_on_factor) instead of a new factorization. Those store W = L₁₁⁻¹P𝔹ᵀ, about
// coupling · m₂/m₁ entries (a cell's reach up the elimination tree is much the same at either size),
// in dense blocks per supernode: taken where W is under half of K's factor (a compact body, whose
// cells reach little of it; on a thin slab W is most of the factor, and factoring again is cheaper)
// and fits in half the memory available (0: unknown, no limit).
bool forward_solves_pay(const AugmentedFactorParts& first_factor, int first_rows, int rows, double available_bytes);

}  // namespace contact3d
