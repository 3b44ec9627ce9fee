// The whole solve of one scene, stage by stage — discretise (K, f) → contact stage (Γc, T_H, 𝔹)
// → dual problem (one factorization; Q, h) → stability (5.1) → dual QP solver → Tresca step →
// fixed point (5.7) → recovery (w, KKT residuals) — skipping what the scene does not need: no
// contact group -> one linear solve; frictionless -> normal multipliers only, one QP; constant
// coefficient -> one Tresca QP; slip-dependent coefficient -> (5.7).
// The result carries everything the writers and the checks need, with its history.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "base/progress.hpp"
#include "contact/contact_face.hpp"
#include "contact/face_thickness.hpp"
#include "contact/foundation_frame.hpp"
#include "contact/partition.hpp"
#include "fem/dof_map.hpp"
#include "friction/fixed_point.hpp"
#include "mesh/mesh.hpp"
#include "model/kkt.hpp"
#include "model/resultant_forces.hpp"
#include "model/scene.hpp"
#include "qp/mpgp.hpp"

namespace contact3d {

// One Tresca (or frictionless) solve of a run: its multipliers and radii, and the whole nodal
// displacement (3 per mesh node) when the scene keeps per-step fields ([output] steps = "all"),
// else empty.
struct SolveStep {
  Eigen::VectorXd lambda, radius, u;
};

// contact.cell_size = "auto": the first solve's cells (2h) left the contact zone unresolved, so the
// scene was solved again with cells of 1.5h (refine_unresolved_contact).
struct PartitionRefinement {
  bool tried = false;
  // Or the body was thinner than a cell of 2h over Γc (contact/face_thickness.hpp), and the one solve
  // took cells of 1.5h from the start; the other fields stay as they are.
  bool started_finer = false;
  double first_cell_size = 0;          // H of the first solve (m)
  double first_penetration_ratio = 0;  // its SolveResult::penetration_ratio
  double first_seconds = 0;            // its stages, also added into SolveResult::seconds
  bool kept_finer = false;             // the answer is the 1.5h solve's
  bool reused_factor = false;          // the 1.5h solve formed its Q from the first solve's factor of K
  std::string outcome;                 // what happened, for the notes and summary.json
};

struct SolveResult {
  // Inputs as discretised.
  DofMap dofs;
  ContactFace face;
  Partition partition;
  int n_primal = 0, n_dual = 0, n_cells = 0;
  double cell_size = 0;  // H actually requested (m)
  // The foundation plane's frame: face, partition, λ and the contact force's (normal, t1, t2) live
  // in it; u, its history and the resultant forces are in the user's axes.
  FoundationFrame frame;

  // Solution.
  Eigen::VectorXd u;           // nodal displacement, 3 per mesh node
  Eigen::VectorXd lambda;      // [λ_n | λ_t1 | λ_t2] per cell (λ_t empty when frictionless)
  Eigen::VectorXd radius;      // disc radii c_i of the last Tresca problem
  Eigen::VectorXd slip_input;  // φ used for the last radii, at contact nodes
  // The state after each Tresca (or frictionless) solve, in order — the fixed point's steps, or the
  // one solve; the last one is the answer above.
  std::vector<SolveStep> steps;

  // How it went.
  bool converged = false;
  std::string status;            // "converged", "iteration_limit", "stagnation", ...
  FixedPointResult fixed_point;  // empty history when no fixed point was needed
  QpResult last_qp;
  int n_mult = 0;                    // multiplications by K⁻¹ in the paper's sense (see DESIGN note in README)
  int qp_iterations = 0;             // MPGP iterations and Newton steps of every QP solve
  int qp_newton_steps = 0;           // of which semismooth Newton steps (each a dense Cholesky of the free size)
  int qp_bordered_newton_steps = 0;  // of which solved through the factor of Q (solver.qp_newton_systems)
  int qp_feasible_newton_steps = 0;  // of which feasible descent steps (qp/ssn.hpp: the target far outside)
  // Bodies held by contact alone with friction: the largest share of friction's hold the loads take along
  // a slide or turn only friction holds (friction_hold, held_by_contact.hpp); −1 where there is none.
  double friction_hold_share = -1;
  // At friction's limit (friction_hold_share 1): how far the answer slides along the motion it leaves
  // undetermined, over the size of the part held by contact (0 otherwise).
  double friction_limit_slide = 0;
  int qp_rounding_stops = 0;  // QP solves (or inner solves) stopped at their rounding floor, within 10x their tolerance
  // Whether those steps switched from the single factor of Q to one in double (bordered_newton.hpp:
  // cond(Q) too large for single's refinement to contract).
  bool qp_bordered_factor_in_double = false;
  int qp_coarse_products = 0;  // of n_mult, columns of the matrix-free Newton steps' blocked coarse products
  // Products Q·v in single precision (solver.qp_precision): through Q's float copy, or matrix-free
  // through the factor's.
  int qp_single_products = 0;
  KktResiduals kkt;
  // Coulomb: max_i |c_i − F̄_i(φ) λ_n,i| / max_i c_i for the final (λ, φ) — the fixed point's own
  // residual (of the order of fixed_point_tol), not part of kkt.max(); 0 for Tresca.
  double coulomb_relation = 0;
  ResultantForces forces;  // applied, contact and reaction forces and their balance
  double wn_plus_L2 = 0, wn_plus_inf = 0;
  // wn_plus_inf / the body's largest nodal displacement less its best-fitting rigid motion along the
  // motions the contact alone holds (all of it where nothing is held; 0 without contact)
  double penetration_ratio = 0;
  // The other side of the cell averages: the largest gap d − w_n left open at a node whose whole hat
  // function lies in pressed cells, over the same displacement (0 without contact).
  double open_gap_ratio = 0;
  bool factor_reused = false;  // Q formed from an earlier solve's factor of K (no factorization of its own)
  double largest_strain = 0;   // the largest principal strain of u in absolute value, over the tetrahedra
  PartitionRefinement refinement;
  double stability_condition = 0;            // estimate of cond(Q) from its Cholesky pivots
  double stability_condition_scaled = 0;     // cond of the Jacobi-scaled Q where cond(Q) > 1e8 (else 0)
  std::vector<std::string> warnings;         // what makes this answer less trustworthy than its residuals say
  std::vector<std::string> notes;            // what the model does that a user may not expect
  double friction_where_separated_area = 0;  // Tresca: area of cells with friction but λ_n = 0
  std::vector<std::pair<std::string, double>> seconds;  // per stage, in order
  double factor_nonzeros = 0;
  double step_solve_fraction =
      1;  // share of nnz(L) one fixed-point step back-substitutes through (DisplacementTrace); 1: a full solve
  std::string schur_method;         // how Q was formed: "augmented", "contactlast", "blocksolve" or "mumps"
  std::string backend = "cholmod";  // the linear-algebra library: "cholmod", "mumps" (called directly) or "petsc-mumps"
  int ranks = 1;                    // MPI ranks of the factorization (the distributed backend)
  int near_null_space = 0;          // rigid-body modes attached to the backend's matrix (the PETSc route: 6)
  std::vector<double> peak_memory_per_rank_mib;  // peak resident memory of each rank at the end
  std::string qp_method;                         // "auto", "mpgp", "mpgp_projcg" or "ssn"
};
// Whether each step's displacement was kept (output.steps resolved to "all"), so steps/ is written.
inline bool steps_written(const SolveResult& res) { return !res.steps.empty() && res.steps.front().u.size() > 0; }

using ProgressCallback = std::function<void(const FixedPointStep&)>;

// `progress` (may be null) gets a line per stage (what starts, how big) and the QP's heartbeat.
SolveResult solve_scene(const Scene& scene, const Mesh& mesh, const ProgressCallback& on_step = {},
                        Progress* progress = nullptr);

// contact.cell_size = "auto": whether the answer on cells of 1.5h replaces the first (2h) one. Only
// where it penetrates less, and a converged answer is never traded for one that did not converge, nor a
// reliable λ for one whose Q is ill-conditioned (stability check's warning: cells nearly dependent).
struct FinerAnswer {
  bool penetrates_less = false;     // its penetration ratio is below the first's
  bool loses_convergence = false;   // it did not converge where the first did
  bool loses_conditioning = false;  // its Q is ill-conditioned where the first's was not
  bool better() const { return penetrates_less && !loses_convergence && !loses_conditioning; }
};
FinerAnswer compare_finer_answer(const SolveResult& first, const SolveResult& finer);

// What a solve would form before factorizing (`contact3d check`): the first partition's cells and
// multipliers, the dense Q's bytes with its working copies against the memory this process can get,
// the dual route solver.schur resolves to (empty: a dense route named by the scene that would be
// refused), and its factor's predicted size. Throws what the solve's contact stage throws (e.g. cells
// violating (5.1) geometrically) and its refusal of a factor that cannot fit.
struct DualPlan {
  int cells = 0, multipliers = 0;
  double cell_size = 0;                         // H (m; the x extent where cells are anisotropic)
  std::string cell_sizes;                       // a graded partition's range of sides (else empty)
  int regions = 1;                              // parts of Γc no cell spans (model/contact_regions.hpp)
  double dense_bytes = 0, available_bytes = 0;  // available 0: unknown
  std::string method;
  std::string route_reason;           // why "auto" took the matrix-free route though the dense Q fits (else empty)
  std::string thin_body;              // contact.cell_size = "auto" found the body thin and starts on cells of 1.5h: why
  std::vector<std::string> warnings;  // the partition's and the memory's, as the solve gives them
  // The CHOLMOD factor the route forms (K's, or K's with the multipliers), from its symbolic analysis,
  // and what the run needs beyond the input (that factor's values, indices and workspace, the dense Q
  // and its working copies); 0 where it is not predicted (MUMPS, contactlast). A factor that cannot fit is
  // refused here, as the solve refuses it.
  double factor_nonzeros = 0, factor_flops = 0, run_bytes = 0;
};
// `thickness`: the run's one measurement over `mesh` (contact/face_thickness.hpp).
DualPlan plan_dual(const Scene& scene, const Mesh& mesh, const FaceThicknessOnce& thickness);

// Positive part of the penetration w_n − d = −u_3 − z on Γc: (L2 norm integrated exactly over the contact triangles,
// max).
std::pair<double, double> normal_violation(const Mesh& mesh, const ContactFace& face, const Eigen::VectorXd& u);

}  // namespace contact3d
