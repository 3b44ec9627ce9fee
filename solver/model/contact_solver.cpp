#include "model/contact_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

#include <Eigen/Dense>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "base/memory.hpp"
#include "base/multiplier_layout.hpp"
#include "contact/contact_operator.hpp"
#include "contact/face_dofs.hpp"
#include "contact/face_thickness.hpp"
#include "distributed/backend.hpp"
#include "fem/assembly.hpp"
#include "fem/dof_map.hpp"
#include "friction/coulomb_map.hpp"
#include "friction/slip_bound.hpp"
#include "friction/tresca_step.hpp"
#include "linalg/blas_buffers.hpp"
#include "linalg/dual_operator.hpp"
#include "linalg/sparse_cholesky.hpp"
#include "mesh/mesh_checks.hpp"
#include "model/contact_regions.hpp"
#include "model/dual_route.hpp"
#include "model/held_by_contact.hpp"
#include "model/input_warnings.hpp"
#include "model/plane_frame.hpp"
#include "model/solution_checks.hpp"
#include "model/solution_fields.hpp"
#include "model/stability_check.hpp"
#include "qp/dual_qp_solver.hpp"
#include "qp/lumped_preconditioner.hpp"

namespace contact3d {
namespace {

// K and f over the free dofs (prescribed components eliminated, their lift in f). With the
// distributed backend this process does not hold K (K_elsewhere): the ranks assemble their columns
// themselves (direct MUMPS route), or the backend copies K and has it freed (release_K). K·w then
// comes element by element, and K is assembled here only if a benchmark asks for a reference
// factorization.
struct Discretisation {
  TetMaterials materials;
  BodyForce body_force;  // each tetrahedron's (tet_body_forces)
  Eigen::SparseMatrix<double> K;
  Eigen::VectorXd f;
  Eigen::VectorXd applied;  // f without the loads of prescribed values (require_loads_press_onto_plane's scale)
  bool K_elsewhere = false;
  ContactHeldMotions held;    // rigid motions the contact alone holds (none: count() = 0)
  bool springs_in_K = false;  // K holds held's pin springs (K_s)
  // Frictionless contact with held.in_plane motions: nothing fixes the body's place along them (their
  // loads balance, or the solve is refused), so the displacement is reported without a rigid part
  // along them, in the least-squares sense over the free dofs.
  bool centre_in_plane = false;

  // The rigid motions whose equilibrium the dual QP enforces as its equalities, μ their displacement:
  // the free ones, or where centre_in_plane those with a normal part only. Frictionless, nothing in
  // the QP acts along a slide (its rows of G are zero): its loads must balance by themselves
  // (require_in_plane_balance), and the QP's equality loop jumped along it by 1e14 (a pressed
  // half-cylinder), leaving the centred displacement rounding at 1e-2 of the body's size.
  Eigen::MatrixXd equality_motions() const {
    return centre_in_plane ? Eigen::MatrixXd(held.field * held.normal_combinations) : held.field;
  }

  std::function<void()> release_K() {
    return [this] {
      Eigen::SparseMatrix<double>().swap(K);  // assigning an empty matrix would keep the capacity
      K_elsewhere = true;
    };
  }
  // K w (never K_s w).
  Eigen::VectorXd stiffness_times(const Mesh& mesh, const DofMap& dofs, const Eigen::VectorXd& w) const {
    if (K_elsewhere) return apply_stiffness(mesh, dofs, materials, w);
    Eigen::VectorXd Kw = K * w;
    if (springs_in_K) held.remove_springs(w, Kw);
    return Kw;
  }
  // The matrix factored: K, or K_s where springs_in_K (for timing and preconditioning, not residuals).
  const Eigen::SparseMatrix<double>& stiffness(const Mesh& mesh, const DofMap& dofs) {
    if (K_elsewhere) {
      K = assemble_stiffness(mesh, dofs, materials);
      K_elsewhere = false;
      springs_in_K = false;
    }
    return K;
  }
};

// `assemble_K` false: K is left to the ranks of the distributed backend (K_elsewhere).
Discretisation discretise(const Scene& scene, const Mesh& mesh, const FaceThicknessOnce& thickness, SolveResult& res,
                          bool assemble_K) {
  check_coordinates_in_range(mesh);
  check_tet_orientation(mesh);
  check_mesh_meaning(mesh, mesh_roles(scene));
  res.dofs = make_dof_map(mesh, scene.clamped, scene.displacements);
  if (res.dofs.n_free == 0) throw InputError("every node is clamped: nothing to solve");
  Discretisation disc{tet_materials(scene, mesh), tet_body_forces(scene, mesh), {}, {}, {}, false, {}, false};
  warn_about_inputs(scene, mesh, res.dofs, disc.materials, thickness, res);
  disc.held = contact_held_motions(mesh, res.dofs, !scene.contact.empty(), scene.user_frame);
  disc.centre_in_plane = disc.held.in_plane_count() > 0 && scene.frictionless();
  res.n_primal = res.dofs.n_free;
  disc.applied = assemble_load(mesh, res.dofs, scene.tractions, disc.body_force);
  disc.f = disc.applied + assemble_lift(mesh, res.dofs, disc.materials);
  if (assemble_K) {
    disc.K = assemble_stiffness(mesh, res.dofs, disc.materials);
    if (disc.held.count()) {
      add_pin_springs(disc.K, disc.held);
      disc.springs_in_K = true;
    }
  } else {
    disc.K_elsewhere = true;
    if (disc.held.count()) add_pin_springs(mesh, res.dofs, disc.materials, disc.held);  // the ranks add them to K
  }
  return disc;
}

// A row of 𝔹 with no free dof (every contact node of the cell has that component prescribed, e.g.
// u_z = 0 given on Γc) breaks (5.1) whatever the cell size: said before anything is factorized.
void require_free_contact_rows(const ContactOperator& op, const Partition& part) {
  Eigen::VectorXd row_size = Eigen::VectorXd::Zero(op.rows());
  for (int j = 0; j < op.B.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(op.B, j); it; ++it) row_size[it.row()] += std::abs(it.value());
  for (int row = 0; row < op.rows(); ++row) {
    if (row_size[row] > 0) continue;
    const int cell = row % op.r;
    const char* component = row < op.r ? "normal" : row < 2 * op.r ? "first tangential" : "second tangential";
    const auto& c = part.cells[static_cast<std::size_t>(cell)];
    throw InputError("cell " + std::to_string(cell) + " of the contact face ([" + number(c.lo.x()) + ", " +
                     number(c.hi.x()) + "] x [" + number(c.lo.y()) + ", " + number(c.hi.y()) +
                     "] in the foundation's plane) has no contact node whose " + component +
                     " displacement is free: boundary.clamped or boundary.displacement prescribes it on all of them, "
                     "so the contact cannot act there (the stability condition (5.1) fails at any cell size); "
                     "prescribe on the contact face only components the contact does not carry");
  }
}

// A cell as large as the whole face (a length meant in another unit, or "20h" on a small face): the
// contact then holds only as the face's average — one normal and one friction force for all of Γc —
// and the run would converge to that without a word. Faces of a handful of nodes are left alone.
void warn_if_one_cell_covers_the_face(SolveResult& res, const std::string& unit) {
  constexpr std::size_t kFewNodes = 9;
  if (res.partition.cells.size() != 1 || res.face.nodes.size() <= kFewNodes) return;
  const Eigen::Vector2d extent = res.face.hi - res.face.lo;
  const double ratio = res.cell_size / extent.maxCoeff();
  res.warnings.push_back("contact.cell_size: one cell of H = " + number(res.cell_size, 3) + " " + unit +
                         " covers the whole contact face (" + number(extent.x(), 3) + " x " + number(extent.y(), 3) +
                         " " + unit + (ratio >= 2 ? ", " + number(ratio, 2) + " times its extent" : std::string()) +
                         ", " + count(static_cast<long long>(res.face.nodes.size())) +
                         " contact nodes): non-penetration and friction hold only as the face's averages, so nodes "
                         "may penetrate and the contact pressure is one value; the method wants cells of about 2h "
                         "(contact.cell_size = \"auto\", the default)");
}

// Γc, its partition T_H into cells and the contact operator 𝔹 (5.4).
ContactOperator contact_stage(const Scene& scene, const Mesh& mesh, SolveResult& res) {
  res.face = make_contact_face(mesh, scene.contact, res.dofs);
  if (std::string w = prescribed_below_plane_warning(mesh, res.face); !w.empty()) res.warnings.push_back(std::move(w));
  if (res.face.held_triangles > 0)
    res.notes.push_back(std::to_string(res.face.held_triangles) + " triangle(s) of the contact groups (area " +
                        number(res.face.held_area, 3) + " " + unit_labels(scene.output.units).length + "²" +
                        ") have every node clamped or prescribed: that condition holds them, not the contact, so "
                        "they are left out of Γc and its cells, and the force there is in the condition's reaction");
  if (res.face.rounded_up > 0)
    res.notes.push_back("nodes of the contact face lie up to " + number(res.face.rounded_up, 3) +
                        " below the foundation plane, within the rounding of the mesh's coordinates (" +
                        number(kPenetrationRounding, 1) + " of its size): taken as on it");
  // H = k·h means k times the typical element extent in each direction (h_xy), so that an
  // anisotropic contact mesh gets rectangles of the same aspect; a length is used as given.
  res.cell_size = scene.cell_size_relative ? scene.cell_size * res.face.h_xy.x() : scene.cell_size;
  PartitionOptions cells;
  cells.cell_size = res.cell_size;
  cells.cell_size_y = scene.cell_size_relative ? scene.cell_size * res.face.h_xy.y() : 0.0;
  cells.per_element_size = scene.cell_size_relative ? scene.cell_size : 0.0;
  cells.length_unit = unit_labels(scene.output.units).length;
  res.partition = make_grid_partition(mesh, res.face, cells, contact_triangle_regions(scene, mesh, res.face),
                                      {res.dofs.fixed, !scene.frictionless()});
  warn_if_one_cell_covers_the_face(res, cells.length_unit);
  ContactOperator op = make_contact_operator(res.face, res.partition, res.dofs, !scene.frictionless());
  res.n_cells = op.r;
  res.n_dual = op.rows();
  require_free_contact_rows(op, res.partition);
  return op;
}

bool is_mumps(DualMethod method) { return method == DualMethod::Mumps || method == DualMethod::MumpsPetsc; }

// The dense Q of `rows` multipliers with its working copies against what this process can get.
struct DenseDualMemory {
  double bytes = 0, available = 0;  // available 0: unknown
  bool fits() const { return !(available > 0 && bytes > 0.9 * available); }
};
DenseDualMemory dense_dual_memory(const QpSettings& qp, int rows) {
  return {dense_dual_bytes_per_entry(qp, rows) * rows * static_cast<double>(rows),
          static_cast<double>(available_memory_bytes())};
}

std::string gib(double bytes) { return number(bytes / (1 << 30), 3) + " GiB"; }

// "auto" in the serial build with a dense Q large enough (kPredictAugmentedShare) that the augmented
// factor beside it may crowd the memory: worth predicting that factor before choosing it.
bool augmented_may_crowd(const Scene& scene, std::optional<DualMethod> chosen, const DenseDualMemory& memory) {
  return scene.solver.dual_method == DualMethod::Auto && chosen == DualMethod::Augmented && memory.available > 0 &&
         memory.bytes > kPredictAugmentedShare * memory.available;
}

// Why the `augmented` factor with the dense Q would crowd the memory where the matrix-free route leaves
// room (dual_route.hpp, augmented_crowds_memory); nullopt where it does not.
std::optional<std::string> augmented_crowds(const FactorPrediction& augmented, int rows,
                                            const DenseDualMemory& memory) {
  if (!augmented_crowds_memory(augmented.factor_nonzeros, rows, memory.bytes, memory.available)) return std::nullopt;
  return "the augmented factor (nnz(L) = " + number(augmented.factor_nonzeros, 3) + ", " +
         gib(8.0 * augmented.factor_nonzeros) + ") with the dense Q and its working copies (" + gib(memory.bytes) +
         ") would need about " + gib(kFactorOverhead * 8.0 * augmented.factor_nonzeros + memory.bytes) + " of the " +
         gib(memory.available) + " this process can get";
}

// Q is dense (m²): where it and its working copies would not fit, or would crowd the memory beside the
// augmented factor, "auto" goes matrix-free (dual_route.hpp) and a dense route the scene named is refused
// rather than dying in the allocator.
DualMethod fit_dual_method(const Scene& scene, DualMethod method, const ContactOperator& op,
                           const Eigen::SparseMatrix<double>& K, Progress& report, SolveResult& res) {
  const DenseDualMemory memory = dense_dual_memory(scene.solver.qp, op.rows());
  const std::optional<DualMethod> chosen = dual_method_for_memory(scene.solver.dual_method, method, memory.fits());
  const std::optional<std::string> crowded =
      augmented_may_crowd(scene, chosen, memory) && K.size() > 0
          ? augmented_crowds(SparseCholesky::predict(K, &op.B), op.rows(), memory)
          : std::nullopt;
  if (crowded) {
    res.notes.push_back(*crowded +
                        ": Q is not formed (solver.schur = \"matrix_free\"); each of its products goes "
                        "through the factor of K alone, and the QP's Newton steps solve their systems by CG — slower "
                        "than the dense route, which a larger contact.cell_size (H) keeps");
    report.stage("  " + *crowded + ": matrix-free dual, each QP product through the factor of K");
    return DualMethod::MatrixFree;
  }
  const std::string sizes = std::to_string(op.r) + " cells (" + std::to_string(op.rows()) +
                            " multipliers): the dense dual operator and its working copies would need " +
                            number(memory.bytes / (1ull << 30)) + " GiB, and this process can get " +
                            number(memory.available / (1ull << 30)) + " GiB";
  if (!chosen)
    throw InputError("the contact partition has " + sizes + "; use a larger contact.cell_size (H)" +
                     (is_mumps(method) ? std::string()
                                       : std::string(", or solver.schur = \"matrix_free\" (Q never formed: each "
                                                     "product through the factor of K)")));
  if (*chosen != DualMethod::MatrixFree) return *chosen;
  if (*chosen != method) {
    res.notes.push_back("the contact partition has " + sizes +
                        ": Q is not formed (solver.schur = \"matrix_free\"); each of its products goes through the "
                        "factor of K, and the QP's Newton steps and the fixed point's predictions solve their systems "
                        "by CG — far slower than the dense route; a larger contact.cell_size (H) keeps the dense Q");
    report.stage(
        "  the dense Q does not fit: matrix-free dual, each QP product through the factor of K (slow; a larger "
        "contact.cell_size keeps the dense Q)");
  }
  return *chosen;
}

// The whole contact force (∫λ over the cells) minus its part on free components (−𝔹ᵀλ summed), both
// in the plane's frame; components at rounding level (1e-12 of the whole) are zero.
Eigen::Vector3d held_share_of_contact_force(const Eigen::Vector3d& whole, const Eigen::Vector3d& on_free) {
  Eigen::Vector3d held = whole - on_free;
  for (int c = 0; c < 3; ++c)
    if (std::abs(held[c]) <= 1e-12 * whole.norm()) held[c] = 0;
  return held;
}

// The yardsticks of total / factorization (benchmarks), in this process: one factorization of K
// as CHOLMOD orders it by itself ("reference_factorization"), and one with the ordering this
// solver uses ("reference_factorization_nd"). Each starts as cold as a fresh process's (the freed
// heap handed back first, not counted), or it would reuse pages the solve touched before it.
void time_reference_factorizations(const Eigen::SparseMatrix<double>& K, StageClock& clock) {
  for (const auto& [ordering, suffix] :
       {std::pair{FillOrdering::CholmodDefault, ""}, std::pair{FillOrdering::QuotientNestedDissection, "_nd"}}) {
    release_freed_memory();
    clock.lap(std::string("reference_setup") + suffix);
    { const SparseCholesky ref(K, ordering); }
    clock.lap(std::string("reference_factorization") + suffix);
  }
}

// The part of φ_h that never changes: at Γc's vertices held in all three components (no contact nodes,
// so no unknowns of the fixed point) their prescribed slip ‖(u1, u2)‖ (FaceDofs::scatter puts the
// prescribed values in), 0 at every other mesh node. A held vertex moved along the plane slips (it was
// taken as 0: an end moved by (2e-5, −1e-5, 0) kept F(0) = 0.3 at its edge for 0.263, λ_t 3% off).
Eigen::VectorXd held_vertex_slip(const FaceDofs& face_dofs, const ContactFace& face, std::size_t n_mesh_nodes) {
  Eigen::VectorXd phi = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_mesh_nodes));
  const Eigen::VectorXd held =
      face_dofs.scatter(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(face_dofs.dofs.size())));
  for (std::size_t j = 0; j < face_dofs.nodes.size(); ++j)
    if (const int v = face_dofs.nodes[j]; face.contact_index[v] < 0)
      phi[v] = std::hypot(held[static_cast<Eigen::Index>(3 * j)], held[static_cast<Eigen::Index>(3 * j + 1)]);
  return phi;
}

// F̄_i(φ) = ∫_{R_i} F(φ_h) dS / meas(R_i) per cell: φ_h the P1 interpolant over all of Γc of φ at the
// contact nodes (the fixed point's unknowns) and, elsewhere, `phi_nodes` as given (held_vertex_slip).
Eigen::VectorXd mean_coefficient(const Scene& scene, const SolveResult& res, Eigen::VectorXd phi_nodes,
                                 const Eigen::VectorXd& phi_contact) {
  for (std::size_t k = 0; k < res.face.nodes.size(); ++k) phi_nodes[res.face.nodes[k]] = phi_contact[k];
  return disc_radii(res.face, res.partition, scene.law, 1.0, phi_nodes);
}

// The radii c_i = F̄_i(φ)·g_i of (5.3); zeros when frictionless (unused).
RadiusRule radius_rule(const Scene& scene, const Mesh& mesh, const SolveResult& res, const FaceDofs& face_dofs) {
  if (scene.frictionless())
    return [r = res.n_cells](const Eigen::VectorXd&, const Eigen::VectorXd&) { return Eigen::VectorXd::Zero(r); };
  return [&scene, &res, held = held_vertex_slip(face_dofs, res.face, mesh.nodes.size())](
             const Eigen::VectorXd& phi_contact, const Eigen::VectorXd& g) {
    return Eigen::VectorXd(mean_coefficient(scene, res, held, phi_contact).cwiseProduct(g));
  };
}

// Where the Jacobi-scaled cond(Q) passes this, an answer to qp_rtol = 1e-6 can be far from the discrete
// solution: a strip with cond(Q) 1.4e8 and qp_max_iterations = 10 left λ_t 13% from the independent
// oracle's (4% at the default cap), where the summary's kkt looked clean.
constexpr double kLooseQpCondition = 1e6;

// A single Tresca QP that did not reach its 1e-10 and was solved on to qp_rtol: a note where that was
// its rounding at the default cap, a warning where the cap was lowered or cond(Q) makes qp_rtol loose.
void say_single_qp_fallback(const Scene& scene, double tight, bool out_of_iterations, SolveResult& res) {
  const int cap = scene.solver.qp.max_iterations;
  const bool cap_lowered = out_of_iterations && cap < QpSettings{}.max_iterations;
  const double cond = dual_condition(res);
  const bool loose = std::isfinite(cond) && cond > kLooseQpCondition;
  const std::string what =
      (out_of_iterations
           ? "the QP stopped at solver.qp_max_iterations = " + std::to_string(cap) + " before the tolerance "
           : std::string("the QP did not reach the tolerance ")) +
      number(tight, 2) + " that a single solve asks for" +
      (cap_lowered ? std::string() : std::string(" (its rounding here)")) +
      "; it was solved to solver.qp_rtol = " + number(scene.solver.qp_rtol, 2) + " instead, from where it stopped";
  if (!cap_lowered && !loose) {
    res.notes.push_back(what + " (kkt gives the residuals reached)");
    return;
  }
  res.warnings.push_back(
      what + ", and its contact forces are only that accurate" +
      (loose ? ": with cond(Q) ≈ " + number(cond, 2) +
                   (res.stability_condition_scaled > 0 ? std::string(" (Jacobi-scaled)") : std::string()) +
                   " they can be well off the discrete solution"
             : std::string()) +
      (cap_lowered ? "; raise solver.qp_max_iterations" : "; a larger contact.cell_size lowers cond(Q)"));
}

// The successive approximations (5.7) when F depends on the slip (on (φ, g = λ_n) for Coulomb);
// otherwise one Tresca (or frictionless) solve, which is then the whole answer.
// That one solve gets the tolerance the last step of a converged fixed point reaches
// (final_step_qp_rtol: 1e-10 by default), not the paper's 1e-6 of a first step: on the thin slab
// (cond(Q) ≈ 1.4e5) a Tresca solve stopped at 1e-6 left the body's displacement 2.6-4.1% from the
// exact discrete answer, at 1e-7 already 2e-5, for 15-30% more dual-solve time.
void iterate_on_slip(const Scene& scene, TrescaStep& tresca, int n_contact_nodes, const ProgressCallback& progress,
                     SolveResult& res) {
  const Eigen::VectorXd phi0 = Eigen::VectorXd::Zero(n_contact_nodes);
  FixedPointSettings fp;
  fp.tol = scene.solver.fixed_point_tol;
  fp.max_iterations = scene.solver.fixed_point_max_iter;
  fp.variant = scene.solver.fixed_point;
  fp.anderson_depth = scene.solver.anderson_depth;
  fp.tail_err = scene.solver.fixed_point_tail_err;
  fp.newton = scene.solver.fixed_point_newton;
  fp.predicted_steps = scene.solver.fixed_point_prediction;
  fp.qp_rtol_per_err = scene.solver.qp_rtol_per_err;
  fp.inexact = scene.solver.inexact_fixed_point;
  fp.hint_context = {scene.law.depends_on_slip(), scene.law.kind == FrictionLaw::Kind::Table,
                     scene.solver.qp.variant == QpVariant::Auto, dual_ill_conditioned(res)};
  if (scene.needs_fixed_point()) {
    if (scene.coulomb()) {
      CoulombMap coulomb(tresca, n_contact_nodes, res.n_cells, scene.law.depends_on_slip());
      fp.blocks = coulomb.blocks();
      res.fixed_point = solve_fixed_point(std::ref(coulomb), coulomb.size(), fp, scene.solver.qp_rtol, progress);
    } else {
      res.fixed_point = solve_fixed_point(std::ref(tresca), n_contact_nodes, fp, scene.solver.qp_rtol, progress);
    }
    res.status = to_string(res.fixed_point.status);
    res.converged = res.fixed_point.status == FixedPointStatus::Converged;
  } else {
    double rtol = final_step_qp_rtol(fp, scene.solver.qp_rtol);
    const auto t0 = std::chrono::steady_clock::now();
    SlipEvaluation eval = tresca(phi0, rtol);
    // The step's work, both solves when there are two (the console printed the second one's alone: 0
    // iterations after a first one of 100 001).
    int qp_iterations = eval.qp_iterations;
    int products = eval.hessian_products;
    if (!eval.ok && rtol < scene.solver.qp_rtol) {
      // That tolerance can lie below what the QP's rounding allows: a block held by contact alone 1 mm
      // above the plane (Tresca) ran 101 786 iterations at 1e-10 and was refused as unbalanced, where
      // 1e-8 converges in 2 000. Solved again, from where it stopped, to the paper's solver.qp_rtol.
      const double tight = rtol;
      const bool out_of_iterations = tresca.last_qp().status == QpStatus::IterationLimit;
      rtol = scene.solver.qp_rtol;
      eval = tresca(phi0, rtol);
      qp_iterations += eval.qp_iterations;
      products += eval.hessian_products;
      if (eval.ok) say_single_qp_fallback(scene, tight, out_of_iterations, res);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    res.converged = eval.ok;
    res.status = eval.ok ? "converged" : "qp_" + to_string(tresca.last_qp().status);
    if (progress) progress({1, 0.0, qp_iterations, products, seconds, rtol});
  }
}

// max_i |c_i − F̄_i(φ)·λ_n,i| / max_i c_i at the end of a Coulomb solve, φ the final slip: how far
// the last Tresca problem's radii are from Coulomb's law for the solution it produced.
double coulomb_relation(const Scene& scene, const Mesh& mesh, const SolveResult& res, const TrescaStep& tresca) {
  const FaceDofs face_dofs(res.face, res.dofs, mesh.nodes.size());
  const Eigen::VectorXd& u_face = tresca.last_face_displacement();  // the last solve's u on Γc: no new K⁻¹ solve
  const Eigen::VectorXd bound = mean_coefficient(scene, res, held_vertex_slip(face_dofs, res.face, mesh.nodes.size()),
                                                 face_dofs.slip(res.face, u_face))
                                    .cwiseProduct(tresca.normal_pressure());
  const double scale = std::max(res.radius.cwiseAbs().maxCoeff(), bound.cwiseAbs().maxCoeff());
  return scale > 0 ? (res.radius - bound).cwiseAbs().maxCoeff() / scale : 0.0;
}

// err(k) <= fixed_point_tol bounds Coulomb's relation max|c − F̄λ_n| / max c only up to a factor (up to
// 3.5e-4 at the default 1e-4 on 300 random bodies); beyond this many times the tolerance the stop came
// from a small change of a sequence that does not contract, and the radii are not yet Coulomb's.
constexpr double kCoulombRelationPerTol = 10;

// A free plate on an incline under a slip-weakening law (random body 3052): 68 steps, the contraction
// factor 1.22, err 9.3e-5 at the stop and the relation 1.6e-3, reported as converged with nothing said.
void warn_if_coulomb_law_unmet(const Scene& scene, SolveResult& res) {
  if (!res.converged || !(res.coulomb_relation > kCoulombRelationPerTol * scene.solver.fixed_point_tol)) return;
  const double q = res.fixed_point.contraction_factor;
  res.warnings.push_back(
      "Coulomb's law holds only to " + number(res.coulomb_relation, 2) +
      " at the answer (kkt.coulomb_relation: the disc radii against F(slip)·λ_n, relative to the largest), more than " +
      number(kCoulombRelationPerTol, 2) + " times solver.fixed_point_tol = " + number(scene.solver.fixed_point_tol, 2) +
      ": the successive approximations stopped on a small change" +
      (std::isfinite(q) && q >= 1 ? " of steps that do not contract (q ≈ " + number(q, 3) + ")" : std::string()) +
      ", so the forces are those of radii Coulomb's law does not yet reproduce; solve with a smaller "
      "solver.fixed_point_tol to see whether they settle (a slip-weakening law near the friction's limit may have "
      "more than one solution)");
}

// A body held by contact alone brought down by more than this share of its size (the larger of its contact
// face's span and its free part's extent): warned.
constexpr double kFarApproachShare = 0.1;

// A body held by contact alone: the dual QP gets the equilibrium of the free rigid motions as its
// equality constraints Gλ = e, and the Tresca step their displacement on Γc.
void hold_by_contact(const Scene& scene, const Discretisation& disc, const ContactOperator& op,
                     const FaceDofs& face_dofs, DualQpSolver& qp, TrescaStep& tresca, Progress& report,
                     SolveResult& res) {
  if (disc.centre_in_plane) require_in_plane_balance(disc.held, disc.f, scene.how_to_add_friction());
  const Eigen::MatrixXd R = disc.equality_motions();
  qp.set_equality((op.B * R).transpose(), R.transpose() * disc.f);
  Eigen::MatrixXd face_field(static_cast<Eigen::Index>(face_dofs.dofs.size()), R.cols());
  for (std::size_t k = 0; k < face_dofs.dofs.size(); ++k)
    face_field.row(static_cast<Eigen::Index>(k)) = R.row(face_dofs.dofs[k]);
  tresca.add_rigid_motions(std::move(face_field));
  const std::string note =
      "held by contact alone: nothing prescribed holds " + disc.held.describe() + "; K made regular by a spring at " +
      std::to_string(disc.held.pins.size()) + " dof(s), the equilibrium along those motions" +
      (disc.centre_in_plane ? std::string(" with a part along the plane's normal") : std::string()) +
      " an equality constraint of the dual";
  report.stage(note);
  res.notes.push_back(note);
  // A body held by contact alone that starts above the plane is brought down onto it by the loads:
  // said, since its displacement then holds that rigid approach (a probe's block 1 mm up came out 1 mm
  // lower with nothing said; a prescribed approach that leaves a gap is warned elsewhere).
  double lowest = INFINITY;
  for (const int v : res.face.nodes) lowest = std::min(lowest, res.face.gap[static_cast<std::size_t>(v)]);
  if (lowest > 0 && std::isfinite(lowest)) {
    const std::string approach =
        "the contact face starts " + number(lowest, 3) +
        " above the foundation plane at its lowest node; held by contact alone, the body is brought "
        "down onto it by the loads" +
        (res.dofs.has_nonzero_prescribed() ? std::string(" and the prescribed displacements") : std::string()) +
        ", and its displacement includes that rigid approach";
    // A gap of a tenth of the body's size or more is rather a foundation left at z = 0 under a mesh in
    // other coordinates (a flange 200 mm across, its sole at z = 250 mm: every u_z came out −250 mm,
    // with this said as a note only).
    const double span = std::max((res.face.hi - res.face.lo).norm(), disc.held.size);
    if (lowest > kFarApproachShare * span)
      res.warnings.push_back(approach + " — " + number(lowest / span, 2) +
                             " times the body's size: if the foundation is meant to be where the face lies, "
                             "place it there (contact.plane_point, contact.plane_normal)");
    else
      res.notes.push_back(approach);
  }
  if (disc.centre_in_plane)
    res.notes.push_back("frictionless contact does not fix " + disc.held.describe_in_plane() +
                        ": the loads along it must balance by themselves (checked before the solve), and the "
                        "displacement is given without a rigid part along it (its mean over the body's nodes, in the "
                        "least-squares sense)");
}

// At this share of friction's hold along a slide or turn that only friction holds, the answer's place
// along it is undetermined (at 1) or hangs on the last digits of the loads and the friction coefficient.
constexpr double kFrictionAtItsLimit = 0.999;

// A body held by contact alone whose loads take friction to its limit along an in-plane motion: every
// pressed cell slides at its bound against that motion, and any further slide along it solves the
// problem as well — the answer is one of many, said (a block on an incline of slope F, which converged
// with nothing said).
void warn_if_friction_at_its_limit(const Scene& scene, const ContactHeldMotions& held, const ContactOperator& op,
                                   const TrescaStep& tresca, SolveResult& res) {
  if (!op.with_friction || held.in_plane_count() == 0) return;
  const FrictionHold hold = friction_hold(held, op, tresca);
  res.friction_hold_share = hold.share;
  if (hold.share < kFrictionAtItsLimit) return;
  const bool at_limit = hold.share >= kFrictionHoldReached;
  // With friction the equality motions are held.field (Discretisation::equality_motions).
  const double slide = part_along(hold.slide, held.field * tresca.history().back().rigid).lpNorm<Eigen::Infinity>();
  if (at_limit) res.friction_limit_slide = slide / held.size;
  res.warnings.push_back(
      (at_limit ? std::string("friction is at its limit")
                : "friction is within " + number(100 * (1 - hold.share), 2) + "% of its limit") +
      ": along " + hold.motion + " the loads take " + number(100 * hold.share, 6) +
      "% of the most the friction can hold along it (every cell with a friction bound slides at it, all against "
      "that motion), so how far the body slides along it is " +
      (at_limit ? "not determined — a further slide along it solves the problem as well — and the displacement given "
                  "is one answer of many (this one moves the body by " +
                      number(slide, 3) + " " + unit_labels(scene.output.units).length + " along it, " +
                      number(slide / held.size, 3) + " times its size)"
                : "barely determined: it hangs on the last digits of the loads and the friction coefficient") +
      "; for a determined answer lower the tangential loads or raise the friction coefficient, or prescribe that "
      "motion (boundary.displacement)");
}

// The displacement at the free dofs after one Tresca solve: w = K⁻¹(f − 𝔹ᵀλ), less the rigid
// motions Rμ that the contact alone holds (held_by_contact.hpp).
Eigen::VectorXd displacement_of(const DualProblem& dual, const Discretisation& disc, const TrescaStep::Solve& solve) {
  Eigen::VectorXd w = dual.displacement(solve.lambda);
  if (disc.held.count()) w -= disc.equality_motions() * solve.rigid;
  if (disc.centre_in_plane) {
    const Eigen::MatrixXd slides = disc.held.field * disc.held.in_plane_combinations;
    w -= slides * (slides.transpose() * slides).ldlt().solve(slides.transpose() * w);
  }
  return w;
}

// A run that did not converge is checked like an answer, but what the checks find is its last
// iterate's: said before each warning, which would otherwise blame the scene (a helper's plate whose
// QP broke down under "mpgp" was told of 353% strain — "check units" —, of equilibrium to 10 times the
// forces — "check supports" — and of 79% penetration); so before each note (a failed iterate's tiny
// strain is not a matter of units). `earlier`: the messages from before the checks (some checks insert
// theirs first).
void say_checks_are_of_the_last_iterate(std::vector<std::string>& messages, const std::vector<std::string>& earlier) {
  for (std::string& message : messages)
    if (std::find(earlier.begin(), earlier.end(), message) == earlier.end())
      message = "of the last iterate of a run that did not converge (not an answer): " + message;
}

// The whole displacement from the final λ, the residuals of (5.4) and the violation of w_n <= 0.
void recover(const Scene& scene, const Mesh& mesh, const Discretisation& disc, const ContactOperator& op,
             const DualProblem& dual, const TrescaStep& tresca, SolveResult& res) {
  const Eigen::VectorXd w = displacement_of(dual, disc, tresca.history().back());
  res.lambda = tresca.lambda();
  res.radius = tresca.radius();
  res.slip_input = tresca.slip_input();
  res.last_qp = tresca.last_qp();
  res.qp_iterations = tresca.qp_iterations();
  res.qp_newton_steps = tresca.newton_steps();
  res.qp_bordered_newton_steps = tresca.bordered_steps();
  res.qp_feasible_newton_steps = tresca.feasible_steps();
  res.qp_rounding_stops = tresca.rounding_stops();
  res.qp_coarse_products = tresca.coarse_products();
  res.qp_single_products = tresca.single_products();
  res.n_mult =
      tresca.products() + 1;  // + h = 𝔹K⁻¹f; forming Q is not counted (not multiplications in the paper's sense)
  res.u = expand_to_nodes(res.dofs, w);
  res.kkt = kkt_residuals(disc.stiffness_times(mesh, res.dofs, w), disc.f, op.B, op.r, op.with_friction, res.radius, w,
                          res.lambda, dual.h(), op.offset);
  std::tie(res.wn_plus_L2, res.wn_plus_inf) = normal_violation(mesh, res.face, res.u);
  res.forces =
      resultant_forces(mesh, res.dofs, disc.materials, scene.tractions, disc.body_force, res.u, op.B, res.lambda);
  res.forces.contact_at_held_nodes = held_share_of_contact_force(contact_force_in_plane_frame(res), res.forces.contact);
  if (scene.coulomb()) {
    res.coulomb_relation = coulomb_relation(scene, mesh, res, tresca);
    warn_if_coulomb_law_unmet(scene, res);
  }
  const std::vector<std::string> warnings_before = res.warnings;
  const std::vector<std::string> notes_before = res.notes;
  check_answer(scene, mesh, largest_deformation(mesh, res.dofs, w, disc.held.field),
               disc.held.count() > 0 || res.dofs.has_nonzero_prescribed(), res);
  if (!res.converged) {
    say_checks_are_of_the_last_iterate(res.warnings, warnings_before);
    say_checks_are_of_the_last_iterate(res.notes, notes_before);
  }
  if (!res.u.allFinite() || !res.lambda.allFinite() || !res.radius.allFinite() || !std::isfinite(res.kkt.max()))
    throw InputError(
        "the solution is not finite: the scene's loads, material or friction values overflow double "
        "precision (check their units); no results were written");
}

// The state after every solve, for the per-step output: λ and the radii as the Tresca step kept
// them, and (for [output] steps = "all") the whole displacement, one back substitution per step
// before the last (whose displacement is the answer's).
void record_steps(const Scene& scene, const DualProblem& dual, const Discretisation& disc, const TrescaStep& tresca,
                  SolveResult& res) {
  const auto& solves = tresca.history();
  const auto n_nodes = static_cast<std::size_t>(res.dofs.n_nodes);
  const bool every_step = resolved(scene.output.steps, n_nodes, solves.size()) == StepOutput::All;
  if (!every_step && scene.output.steps == StepOutput::Auto && solves.size() > 1)
    res.notes.push_back("the " + std::to_string(solves.size()) +
                        " steps of the fixed point are not written one by one (" + std::to_string(n_nodes) +
                        " nodes × " + std::to_string(solves.size()) + " steps passes output.steps = \"auto\"'s " +
                        std::to_string(kStepOutputAutoNodeSteps) +
                        "): body.vtu and contact.vtu hold the answer; output.steps = \"all\" writes each step");
  res.steps.clear();
  for (std::size_t k = 0; k < solves.size(); ++k) {
    SolveStep step{solves[k].lambda, solves[k].radius, Eigen::VectorXd()};
    if (every_step)
      step.u = k + 1 == solves.size() ? res.u : expand_to_nodes(res.dofs, displacement_of(dual, disc, solves[k]));
    res.steps.push_back(std::move(step));
  }
}

// The stage running now and what it holds, for an out-of-memory message that says where and why.
struct RunningStage {
  std::string name = "assembly";
  std::string holds;  // e.g. "a factor with 2.3e+07 nonzeros (0.17 GiB)"
  void enter(std::string stage, std::string what) {
    name = std::move(stage);
    holds = std::move(what);
  }
};

double stage_seconds(const SolveResult& res, const std::string& stage) {
  for (const auto& [name, seconds] : res.seconds)
    if (name == stage) return seconds;
  return 0;
}

// After CHOLMOD's symbolic analysis: the factor's predicted size on the progress line, and a clear
// error before the numeric factorization when the factor cannot fit in the memory available. What the
// process still needs from there: the factor's values and CHOLMOD's indices and workspace (kFactorOverhead
// times the values), then the dense Q with its working copies (`dense_dual_bytes`, 0 where Q is not
// formed). The test counted the factor alone, and a helper's foot of 1.19 million unknowns (a 14 GiB
// factor, 12 009 multipliers) passed it and peaked at 21.2 GiB, 421 MB of the machine left; with Q it
// needs about 19.5 of the 19.4 GiB the process could get. Measured on a plate of 185 550 unknowns: 0.31
// GiB held at the check, 1.86 GiB at the peak (a 0.92 GiB factor, Q 0.39 GiB in double). Where the need
// comes within kTightMemory of what the process can get, a warning says so before the factorization: the
// system may kill the run without a message (under ulimit -v, CHOLMOD's own refusal follows: the brick at
// n = 24 needs about 0.75 GiB of address space there, 1.45 times its factor's values).
// (kFactorOverhead and kTightMemory: model/dual_route.hpp.)
// What the dual adds to the factor: the dense Q with its working copies, or on the matrix-free route the
// float copy of K's factor for the QP's single products (4 bytes per entry of L, where its budget allows:
// add_single_products) — a helper's matrix-free slab of 27 648 multipliers was predicted at 3.2 GiB and
// peaked at 4.27, the copy's 0.95 GiB.
struct DualMemoryNeed {
  double dense_q = 0;
  bool single_factor_copy = false;
  double copy_bytes(double lnz, double available) const {
    const double copy = 4.0 * lnz;
    return single_factor_copy && copy <= single_factor_budget(available) ? copy : 0.0;
  }
};
DualMemoryNeed matrix_free_need(const QpSettings& qp, int rows) {
  return {0.0, uses_single_products(qp.precision, rows)};
}

// What the run needs beyond the mesh and K: the factor with `lnz` nonzeros and what the dual adds.
double run_need_bytes(double lnz, const DualMemoryNeed& dual, double available) {
  return kFactorOverhead * 8.0 * lnz + dual.dense_q + dual.copy_bytes(lnz, available);
}

// Throws the refusal where that need cannot fit; returns the warning where the memory is tight, else an
// empty string.
std::string require_factor_fits(double lnz, const DualMemoryNeed& dual) {
  const double bytes = 8.0 * lnz;  // its values
  const double available = static_cast<double>(available_memory_bytes());
  const double copy = dual.copy_bytes(lnz, available);
  const double need = run_need_bytes(lnz, dual, available);
  const std::string needs =
      "its factor has " + number(lnz, 3) + " nonzeros (" + gib(bytes) + "; with CHOLMOD's indices and workspace" +
      (dual.dense_q > 0 ? " and the dense Q of the dual (" + gib(dual.dense_q) + ")" : std::string()) +
      (copy > 0 ? " and its single-precision copy for the QP's products (" + gib(copy) + ")" : std::string()) +
      " the run needs about " + gib(need) + " more) and this process can get " + gib(available);
  if (available > 0 && need > available)
    throw InputError("not enough memory for the factorization: " + needs +
                     "; use a coarser mesh (mesh.n, or the mesh parameters' h), a machine with more memory, or the "
                     "distributed build's MUMPS with its factor on disk (solver.out_of_core_dir, README: \"Beyond "
                     "one machine\")");
  if (available > 0 && need > kTightMemory * available)
    return "memory is tight: " + needs +
           ", so the system may kill the run (out of memory) without a message; a coarser mesh leaves room";
  return {};
}

AnalysisObserver factor_size_check(Progress& report, RunningStage* stage = nullptr, DualMemoryNeed dual = {},
                                   std::vector<std::string>* warnings = nullptr) {
  return [&report, stage, dual, warnings](double lnz, double flops) {
    const std::string nonzeros = number(lnz, 3), bytes = bytes_text(8.0 * lnz);
    if (stage) stage->holds = "a factor with " + nonzeros + " nonzeros (" + bytes + ")";
    report.stage("  factor: nnz(L) = " + nonzeros + " (" + bytes + "), " + number(flops / 1e9, 3) + " GFlop");
    std::string tight = require_factor_fits(lnz, dual);
    if (!tight.empty() && warnings) {
      report.stage("  warning: " + tight);
      warnings->push_back(std::move(tight));
    }
  };
}

// Auto: MUMPS in the distributed build, the augmented CHOLMOD factor otherwise.
DualMethod resolved_dual_method(DualMethod method) {
  if (method != DualMethod::Auto) return method;
  return distributed::available() ? DualMethod::Mumps : DualMethod::Augmented;
}

// The backend the settings ask for, refused before any work where it cannot act (and by `check`): MUMPS
// in the serial build (refused once only after meshing and assembly, while check said ok), MUMPS's
// out-of-core mode (solver.out_of_core_dir) on another route or without a contact face.
void require_backend(const Scene& scene, DualMethod method) {
  if (is_mumps(method) && !scene.contact.empty() && !distributed::available())
    throw InputError("solver.schur = \"" + std::string(name_of(method, kDualMethodNames)) +
                     "\" needs the distributed build: `make build-mpi`, then `mpirun -np P build-mpi/contact3d solve "
                     "SCENE`");
  if (scene.solver.out_of_core_dir.empty()) return;
  if (method != DualMethod::Mumps)
    throw InputError(
        "solver.out_of_core_dir is MUMPS's out-of-core mode: it needs " +
        std::string(distributed::available()
                        ? "solver.schur = \"mumps\" (MUMPS called directly; "
                        : "the distributed build with solver.schur = \"mumps\" (`make build-mpi`, `mpirun -np P "
                          "build-mpi/contact3d solve SCENE`; ") +
        "the factorization chosen here, " + std::string(name_of(method, kDualMethodNames)) +
        ", keeps its factor in memory): set solver.schur = \"mumps\" or remove the option");
  if (scene.contact.empty())
    throw InputError(
        "solver.out_of_core_dir: this scene has no contact group, so it is one linear solve by CHOLMOD "
        "on rank 0, with its factor in memory; remove the option or add a [boundary] contact group");
}

std::unique_ptr<DualProblem> make_dual_problem(DualMethod method, const DualProblemInput& input,
                                               const SolverSettings& settings, StageClock& clock) {
  if (method == DualMethod::Mumps)
    return distributed::make_mumps_dual_problem(input, clock,
                                                {distributed::MumpsRoute::Direct, settings.out_of_core_dir.string()});
  if (method == DualMethod::MumpsPetsc)
    return distributed::make_mumps_dual_problem(input, clock, {distributed::MumpsRoute::ThroughPetsc, ""});
  return make_cholmod_dual_problem(method, input, clock);
}

// No contact group: one linear solve.
void solve_without_contact(const Scene& scene, const Mesh& mesh, const Discretisation& disc, StageClock& clock,
                           SolveResult& res, Progress& report) {
  const Eigen::SparseMatrix<double> no_rows(0, disc.K.cols());
  report.stage("no contact group: one linear solve (CHOLMOD), " + count(res.n_primal) + " rows");
  const auto dual = make_cholmod_dual_problem(
      DualMethod::BlockSolve, {disc.K, no_rows, disc.f, {}, Eigen::VectorXd(), factor_size_check(report)}, clock);
  res.factor_nonzeros = dual->factor_nonzeros;
  const Eigen::VectorXd w = dual->displacement(Eigen::VectorXd());
  res.u = expand_to_nodes(res.dofs, w);
  res.kkt.equilibrium = (disc.K * w - disc.f).norm() / std::max(disc.f.norm(), 1e-300);
  res.forces = resultant_forces(mesh, res.dofs, disc.materials, scene.tractions, disc.body_force, res.u, no_rows,
                                Eigen::VectorXd());
  flag_motionless(scene, res);
  flag_large_strain(mesh, res);
  note_body_below_plane_without_contact(mesh, res);
  res.n_mult = 1;
  res.converged = true;
  res.status = "converged";
  clock.lap("solve");
  if (scene.solver.reference_factorization) time_reference_factorizations(disc.K, clock);
}

}  // namespace

std::pair<double, double> normal_violation(const Mesh& mesh, const ContactFace& face, const Eigen::VectorXd& u) {
  double l2sq = 0, inf = 0;
  for (const auto& tri : face.triangles) {
    Polygon poly =
        triangle_polygon(mesh.nodes[tri[0]].head<2>(), mesh.nodes[tri[1]].head<2>(), mesh.nodes[tri[2]].head<2>());
    // Penetration w_n − d: the normal displacement beyond the initial gap.
    const Eigen::Vector3d wn(-u[3 * tri[0] + 2] - face.gap[tri[0]], -u[3 * tri[1] + 2] - face.gap[tri[1]],
                             -u[3 * tri[2] + 2] - face.gap[tri[2]]);
    inf = std::max(inf, wn.maxCoeff());
    if (wn.maxCoeff() <= 0) continue;
    std::vector<double> levels = {-wn[0], -wn[1], -wn[2]};
    poly = clip_by_levels(poly, levels);
    if (poly.empty()) continue;
    std::vector<double> values(poly.size());
    for (std::size_t k = 0; k < poly.size(); ++k) values[k] = std::max(0.0, poly[k].bary.dot(wn));
    l2sq += integral_linear_squared(poly, values);
  }
  return {std::sqrt(l2sq), std::max(inf, 0.0)};
}

namespace {

void describe_contact(Progress& report, const SolveResult& res, const ContactOperator& op) {
  report.stage("contact: " + count(res.face.triangles.size()) + " triangles and " + count(res.face.nodes.size()) +
               " nodes on Γc; " + count(op.r) + (op.r == 1 ? " cell" : " cells") + " of T_H (" + cell_sizes(res) +
               describe_regions(res.partition.regions) + "), " + count(op.rows()) + " multipliers");
}

std::string describe_dual_solve(const Scene& scene) {
  return std::string("dual solve: ") +
         (scene.needs_fixed_point() ? "successive approximations (5.7), one QP per step"
          : scene.frictionless()    ? "one frictionless QP"
                                    : "one Tresca QP") +
         " (" + name_of(scene.solver.qp.variant, kQpVariantNames) + ")";
}

// The QP's single-precision products on the matrix-free route (MPGP's updates, CG where its tolerance
// allows, the coarse products; dual_qp_solver.hpp) where QpSettings::precision asks for them and a
// float copy of the factor fits its budget (single_factor_budget).
void add_single_products(DualProblem& dual, const QpSettings& settings, MatrixFreeQ& q,
                         std::vector<std::string>& notes) {
  if (!uses_single_products(settings.precision, dual.size())) return;
  const double available = static_cast<double>(available_memory_bytes());
  if (dual.prepare_single_products(single_factor_budget(available))) {
    q.single_product = [&dual](const Eigen::VectorXd& v) { return dual.apply_Q_single(v); };
    q.single_block_product = [&dual](const Eigen::MatrixXd& V) { return dual.apply_Q_block_single(V); };
    return;
  }
  notes.push_back(
      "the QP's products stay in double precision: a single-precision copy of the factor would take more "
      "than " +
      number(100 * kSingleFactorShare) + "% of the " + gib(available) + " available");
}

// 𝔹𝔹ᵀ and 𝔹K𝔹ᵀ for the matrix-free Newton steps' lumped preconditioner (qp/lumped_preconditioner.hpp)
// where they fit (lumped_operators_fit); null otherwise, with a note. K is still held here: only the
// MUMPS backend releases it, and it forms a dense Q.
std::shared_ptr<const LumpedOperators> lumped_operators(const ContactOperator& op, const Eigen::SparseMatrix<double>& K,
                                                        std::vector<std::string>& notes) {
  if (K.rows() == 0) return nullptr;
  auto lumped = std::make_shared<LumpedOperators>(make_lumped_operators(op.B, K));
  const double bytes = lumped_operator_bytes(*lumped), available = static_cast<double>(available_memory_bytes());
  if (lumped_operators_fit(bytes, available)) return lumped;
  notes.push_back(
      "the Newton steps' CG goes with the diagonal as its fine level: the lumped preconditioner's 𝔹𝔹ᵀ and "
      "𝔹K𝔹ᵀ would take " +
      gib(bytes) + " of the " + gib(available) + " available (more than " + number(100 * kLumpedShare) +
      "%); expect more QP products");
  return nullptr;
}

// A matrix-free Q for the QP: its products and diagonal and, where blocked products pay (through the
// factor, not W), the coarse groups of its Newton steps' two-level preconditioner: the cells in
// aggregates of about a 64th of Γc (at least 2 × 2 cells), each component apart. Where W is kept
// (a body whose face reaches little of the factor) a block costs its columns' products, and CG
// with the diagonal did not need the coarse space there (the paper's brick: 738 products with it
// off, 1 591 on). Nor where its arrays would not fit (coarse_space_fits): a note says so. With the
// coarse space, and only there, the lumped operators for its fine level (qp/reduced_cg.hpp) where
// solver.qp_cg_preconditioner asks for them.
MatrixFreeQ matrix_free_q(DualProblem& dual, const ContactOperator& op, const Partition& partition,
                          const QpSettings& settings, const Eigen::SparseMatrix<double>& K,
                          std::vector<std::string>& notes) {
  constexpr double kAggregates = 64;
  MatrixFreeQ q;
  q.product = [&dual](const Eigen::VectorXd& v) { return dual.apply_Q(v); };
  q.diagonal = dual.Q_diagonal();
  if (!dual.blocks_pay()) return q;
  add_single_products(dual, settings, q, notes);
  q.block_product = [&dual](const Eigen::MatrixXd& V) { return dual.apply_Q_block(V); };
  const int side = std::max(2, static_cast<int>(std::ceil(std::sqrt(op.r / kAggregates))));
  int count = 0;
  const std::vector<int> aggregate = cell_aggregates(partition, side, count);
  const MultiplierLayout layout = op.layout();
  const int groups = (layout.with_friction ? 3 : 1) * count;
  const double available = static_cast<double>(available_memory_bytes());
  if (!coarse_space_fits(layout.size(), groups, available)) {
    notes.push_back("the Newton steps' CG goes without its two-level preconditioner: its " + std::to_string(groups) +
                    " coarse vectors would take " + gib(coarse_space_bytes(layout.size(), groups)) + " of the " +
                    gib(available) + " available (more than " + number(100 * kCoarseSpaceShare) +
                    "%); expect more QP products");
    return q;
  }
  q.coarse_group.resize(static_cast<std::size_t>(layout.size()));
  for (int i = 0; i < op.r; ++i) {
    q.coarse_group[static_cast<std::size_t>(layout.normal(i))] = aggregate[static_cast<std::size_t>(i)];
    if (!layout.with_friction) continue;
    q.coarse_group[static_cast<std::size_t>(layout.t1(i))] = count + aggregate[static_cast<std::size_t>(i)];
    q.coarse_group[static_cast<std::size_t>(layout.t2(i))] = 2 * count + aggregate[static_cast<std::size_t>(i)];
  }
  if (settings.cg_preconditioner == CgPreconditioner::Lumped) q.lumped = lumped_operators(op, K, notes);
  return q;
}

// contact.cell_size = "auto": the first solve's factor of K, kept for a second solve with cells of
// 1.5h (the same K, another 𝔹), which forms its Q from it where forward solves cost less than
// factoring again (forward_solves_pay, model/dual_route.hpp).
struct KeptFactor {
  std::shared_ptr<const SparseCholesky> factor;
  // K, for the reference factorizations (solver.reference_factorization), timed once after the last
  // solve (time_kept_reference): timed after the first, they needed its factor freed, and the second solve
  // factored K again where a user's run reuses it (the filleted block: ratio 2.61 where the user's run
  // costs 1.77).
  Eigen::SparseMatrix<double> K;
};

// The reference factorizations of the K kept by the solves of contact.cell_size = "auto", into `res`.
void time_kept_reference(const Scene& scene, KeptFactor& kept, SolveResult& res) {
  if (!scene.solver.reference_factorization || kept.K.size() == 0) return;
  kept.factor.reset();
  StageClock clock(res.seconds, true);
  time_reference_factorizations(kept.K, clock);
  kept.K.resize(0, 0);
}

// The dual problem: on the kept factor where that pays, else by the route's own factorization (whose
// factor is then kept, where there is a KeptFactor to keep it in).
std::unique_ptr<DualProblem> dual_problem(DualMethod method, const DualProblemInput& input, const Scene& scene,
                                          KeptFactor* kept, StageClock& clock, Progress& report, SolveResult& res) {
  const int rows = static_cast<int>(input.B.rows());
  if (kept && kept->factor && method == DualMethod::Augmented &&
      forward_solves_pay(augmented_factor_parts(*kept->factor), kept->factor->trailing_size(), rows,
                         static_cast<double>(available_memory_bytes()))) {
    report.stage("factorization: none, the first solve's factor of K is reused (Q by forward solves of 𝔹 through it)");
    res.factor_reused = true;
    return make_dual_problem_on_factor(kept->factor, input, clock);
  }
  if (kept) kept->factor.reset();  // not reused: freed before K is factored again
  report.stage("factorization (" +
               std::string(is_mumps(method) ? "MUMPS on " + count(distributed::ranks()) + " ranks" : "CHOLMOD") + ", " +
               name_of(method, kDualMethodNames) + ")");
  std::unique_ptr<DualProblem> dual = make_dual_problem(method, input, scene.solver, clock);
  if (kept) kept->factor = dual->factor_to_share();
  return dual;
}

// A refusal with the run's warnings so far appended (they are printed with it, not before it: a
// solve prints its warnings at the end).
std::string with_input_warnings(const std::string& refusal, const std::vector<std::string>& all_warnings) {
  std::vector<std::string> warnings;
  for (const std::string& w : all_warnings)
    if (!warns_of_accuracy_only(w)) warnings.push_back(w);
  if (warnings.empty()) return refusal;
  std::string text = refusal + (warnings.size() == 1 ? " (this input's warning, which may be its cause: "
                                                     : " (this input's warnings, which may be its cause: ");
  for (std::size_t i = 0; i < warnings.size(); ++i) text += (i ? "; " : "") + warnings[i];
  return text + ")";
}

// The factorization stage: K with 𝔹 (K alone on the matrix-free route), through which the dual problem
// (5.5) is formed — Q dense, or its products through the factor — once the contact alone is known to
// hold what it must (require_free_parts_on_contact_face, require_loads_press_onto_plane).
std::unique_ptr<DualProblem> factor_with_multipliers(const Scene& scene, const Mesh& mesh, Discretisation& disc,
                                                     const ContactOperator& op, const FaceDofs& face_dofs,
                                                     DualMethod method, bool K_on_ranks, KeptFactor* kept,
                                                     StageClock& clock, Progress& report, RunningStage& stage,
                                                     SolveResult& res) {
  const bool matrix_free = method == DualMethod::MatrixFree;
  stage.enter("factorization", matrix_free ? "the sparse factor of K (" + count(res.n_primal) + " rows)"
                                           : "the sparse factor of K with the multipliers (" +
                                                 count(res.n_primal + op.rows()) + " rows)");
  if (disc.held.count()) {
    require_free_parts_on_contact_face(disc.held, face_dofs.dofs);
    require_loads_press_onto_plane(disc.held, disc.f, disc.applied);
  }
  StiffnessSource source{mesh, res.dofs, disc.materials};
  if (!disc.springs_in_K)
    for (std::size_t p = 0; p < disc.held.pins.size(); ++p)
      source.springs.emplace_back(disc.held.pins[p], disc.held.pin_springs[p]);
  DualProblemInput input{
      disc.K,
      op.B,
      disc.f,
      face_dofs.dofs,
      op.offset,
      factor_size_check(report, &stage,
                        matrix_free ? matrix_free_need(scene.solver.qp, op.rows())
                                    : DualMemoryNeed{dense_dual_memory(scene.solver.qp, op.rows()).bytes, false},
                        &res.warnings),
      disc.release_K(),
      K_on_ranks ? &source : nullptr};
  if (method == DualMethod::MumpsPetsc) input.near_null_space = rigid_body_modes(mesh, res.dofs);
  input.report = [&report](const std::string& line) { report.stage(line); };
  std::unique_ptr<DualProblem> dual = [&] {
    const Progress::Watch factoring(report, method == DualMethod::MatrixFree
                                                ? "factorization of K, then h and Q's diagonal by forward solves"
                                                : "factorization");
    return dual_problem(method, input, scene, kept, clock, report, res);
  }();
  const double done_s = stage_seconds(res, "factorization") + stage_seconds(res, "dual");
  if (matrix_free)
    report.stage("  done in " + number(done_s, 3) + " s (factor, h and Q's diagonal); Q: " + count(op.rows()) + " x " +
                 count(op.rows()) + ", not formed");
  else
    report.stage("  done in " + number(done_s, 3) + " s (factor and Q); dual operator Q: " + count(op.rows()) + " x " +
                 count(op.rows()) + " dense (" + number(8.0 * op.rows() * op.rows() / (1 << 20), 3) + " MiB)");
  return dual;
}

// The dual QP (5.5) on the dense Q with the stability check's factor of it (`q_factor`, for the Newton
// steps), or on the matrix-free route's products through the factor of K.
DualQpSolver dual_qp(bool matrix_free, DualProblem& dual, const ContactOperator& op, const Discretisation& disc,
                     double q_norm, std::shared_ptr<DualOperatorFactor> q_factor, const QpSettings& settings,
                     SolveResult& res) {
  if (matrix_free)
    return DualQpSolver(matrix_free_q(dual, op, res.partition, settings, disc.K, res.notes), dual.h(), op.r,
                        op.with_friction, q_norm, settings);
  return DualQpSolver(dual.Q(), dual.h(), op.r, op.with_friction, q_norm, settings, std::move(q_factor));
}

// What summary.json says of the route taken (solver.schur, the QP, the backend and its ranks), with a note
// where the ranks' binding or a one-process route under mpirun costs time.
void record_route(const Scene& scene, DualMethod method, const DualProblem& dual, SolveResult& res) {
  res.schur_method = dual.method;
  res.qp_method = name_of(scene.solver.qp.variant, kQpVariantNames);
  res.factor_nonzeros = dual.factor_nonzeros;
  res.step_solve_fraction = dual.step_solve_fraction;
  res.backend = dual.backend;
  res.near_null_space = dual.near_null_space;
  res.ranks = is_mumps(method) ? distributed::ranks() : 1;
  if (is_mumps(method))
    if (std::string note = distributed::core_binding_note(); !note.empty()) res.notes.push_back(std::move(note));
  if (!is_mumps(method) && distributed::ranks() > 1)  // a route of one process, started under mpirun
    res.notes.push_back("solver.schur = \"" + std::string(name_of(method, kDualMethodNames)) +
                        "\" solves on rank 0 alone, the other " + std::to_string(distributed::ranks() - 1) +
                        " rank(s) waiting: solver.schur = \"mumps\" or \"mumps_petsc\" spreads the factorization "
                        "over them");
}

// solver.reference_factorization: the yardstick of total / factorization, one factorization of K in the
// same process, timed here once the solve's own factor is freed (two big factors need not fit at once) —
// or after the last solve of contact.cell_size = "auto", which may still use the kept factor
// (time_kept_reference).
void time_reference(const Mesh& mesh, Discretisation& disc, DualProblem& dual, KeptFactor* kept, StageClock& clock,
                    SolveResult& res) {
  dual.release_factor();
  const Eigen::SparseMatrix<double>& K = disc.stiffness(mesh, res.dofs);  // assembled again if released
  if (kept)
    kept->K = K;
  else
    time_reference_factorizations(K, clock);
}

// The stages of one solve in the foundation plane's frame (the README's data flow), into `res`. `kept`:
// where the factor of K is kept for a second solve with other cells (contact.cell_size = "auto"), or null.
void run_stages(const Scene& scene, const Mesh& mesh, const FaceThicknessOnce& thickness,
                const ProgressCallback& on_step, Progress& report, RunningStage& stage, KeptFactor* kept,
                SolveResult& res) {
  StageClock clock(res.seconds, scene.solver.reference_factorization);
  report.stage("assembly: " + count(mesh.nodes.size()) + " nodes, " + count(mesh.tets.size()) + " tetrahedra");
  DualMethod method = resolved_dual_method(scene.solver.dual_method);
  require_backend(scene, method);
  const bool K_on_ranks = method == DualMethod::Mumps && !scene.contact.empty();
  Discretisation disc = discretise(scene, mesh, thickness, res, !K_on_ranks);
  clock.lap("assembly");
  report.stage("  " + count(res.n_primal) + " unknowns, " +
               (K_on_ranks ? "K assembled by the " + count(distributed::ranks()) + " ranks with the factorization"
                           : "nnz(K) = " + count(disc.K.nonZeros())));
  // `clock` writes into res.seconds: res is filled in place (a moved res lost the "solve" stage's time)
  if (scene.contact.empty()) return solve_without_contact(scene, mesh, disc, clock, res, report);

  stage.enter("contact", "the contact face and its partition");
  const ContactOperator op = contact_stage(scene, mesh, res);
  clock.lap("contact");
  describe_contact(report, res, op);
  method = fit_dual_method(scene, method, op, disc.K, report, res);
  const bool matrix_free = method == DualMethod::MatrixFree;

  const FaceDofs face_dofs(res.face, res.dofs, mesh.nodes.size());
  std::unique_ptr<DualProblem> dual =
      factor_with_multipliers(scene, mesh, disc, op, face_dofs, method, K_on_ranks, kept, clock, report, stage, res);

  stage.enter("stability check", matrix_free ? "the factor of 𝔹𝔹ᵀ and Lanczos steps on Q (one K⁻¹ solve each)"
                                             : "copies of the dense Q (" + gib(2 * 8.0 * op.rows() * op.rows()) + ")");
  double q_norm = 0;  // once: for cond(Q) and for MPGP's step ᾱ
  std::shared_ptr<DualOperatorFactor> q_factor = [&] {
    const Progress::Watch checking(report, "stability check");  // a dense Cholesky of Q: m³/3 flops
    return check_dual_stability(*dual, q_norm, op, scene.solver.qp, dense_dual_memory(scene.solver.qp, op.rows()).bytes,
                                report, res);
  }();
  clock.lap("stability");

  stage.enter("dual solve", matrix_free ? std::string("the QP's vectors, each product through the factor of K")
                                        : "the QP's working copies of Q (" +
                                              gib((dense_dual_bytes_per_entry(scene.solver.qp, op.rows()) - 8) *
                                                  op.rows() * op.rows()) +
                                              ")");
  DualQpSolver qp = dual_qp(matrix_free, *dual, op, disc, q_norm, std::move(q_factor), scene.solver.qp, res);
  qp.report_progress_to(&report);
  TrescaStep tresca(*dual, qp, face_dofs, res.face, radius_rule(scene, mesh, res, face_dofs),
                    Eigen::VectorXd::Constant(op.r, scene.slip_bound));
  if (disc.held.count()) hold_by_contact(scene, disc, op, face_dofs, qp, tresca, report, res);
  report.stage(describe_dual_solve(scene));
  iterate_on_slip(scene, tresca, static_cast<int>(res.face.nodes.size()), on_step, res);
  if (disc.held.count()) {
    require_held(disc.held, disc.equality_motions(), disc.f, op, res.partition, qp, tresca, scene.coulomb());
    warn_if_friction_at_its_limit(scene, disc.held, op, tresca, res);
  }
  clock.lap("dual_solve");

  stage.enter("recovery",
              "the displacement of every step (" + gib(8.0 * 3 * mesh.nodes.size() * tresca.history().size()) + ")");
  report.stage("recovery: displacement, residuals, forces");
  recover(scene, mesh, disc, op, *dual, tresca, res);
  res.qp_bordered_factor_in_double = qp.newton_factor_switched_to_double();
  clock.lap("postprocess");
  record_steps(scene, *dual, disc, tresca, res);
  clock.lap("step_fields");
  record_route(scene, method, *dual, res);
  res.peak_memory_per_rank_mib = distributed::peak_memory_per_rank_mib();
  if (scene.solver.reference_factorization) time_reference(mesh, disc, *dual, kept, clock, res);
}

// run_stages, whose refusal carries the warnings given before it: they often name its cause (two stacked
// boxes not joined, refused as a part with no node on Γc, or young = 210 meant in GPa, refused for a
// rigid displacement thousands of times the body's size — their warnings were lost with the run).
// A refusal that contact.cell_size = "auto" retries with smaller cells passes unchanged.
SolveResult solve_stages(const Scene& scene, const Mesh& mesh, const FaceThicknessOnce& thickness,
                         const ProgressCallback& on_step, Progress& report, RunningStage& stage,
                         KeptFactor* kept = nullptr) {
  SolveResult res;
  try {
    run_stages(scene, mesh, thickness, on_step, report, stage, kept, res);
  } catch (const ContactZoneTooCoarse& e) {
    if (res.warnings.empty() || scene.cell_size_auto) throw;
    throw ContactZoneTooCoarse(with_input_warnings(e.what(), res.warnings));
  } catch (const InputError& e) {
    if (res.warnings.empty()) throw;
    throw InputError(with_input_warnings(e.what(), res.warnings));
  }
  return res;
}

// contact.cell_size = "auto": cells of 2h leave the contact zone unresolved when the body deforms
// inside a cell (flag_unresolved_contact, the warning's level: a contact strip one or two cells wide
// under a cylinder, a body about as thin as a cell), and the cell averages then let it penetrate: a
// half-cylinder pushed 2 mm at h = 0.03 had its normal force 19% below FreeFEM's with cells of 2h,
// 0.2% with cells of 1.5h; the thin slab at h = t 91% ↔ 11% (results/crosscheck/slab_series*.md). So
// the scene is solved again with cells of 1.5h, and that answer is kept when it penetrates less (and
// converged, if the first did). Smaller cells raise cond(Q) and can break the stability (5.1) (cells
// of 1h on the slab: cond ≈ 1e16), so 1.5h is the only step taken, and a refused or failed finer
// solve leaves the first answer (with its warning).

// The scene with cells of 1.5h, as "auto" takes them (kRefinedCellSize), and no further choice.
Scene with_refined_cells(const Scene& scene) {
  Scene finer = scene;
  finer.cell_size = kRefinedCellSize;
  finer.cell_size_auto = false;
  return finer;
}

// contact.cell_size = "auto" on a body thinner over most of Γc (FaceThickness's area-weighted median)
// than this share of a cell of 2h: the 2h solve would be unresolved (a body this thin bends inside a
// cell) and solved again, so it starts with cells of 1.5h. Measured with the default settings, t / H
// with H twice the measured element size: the slab (t = 0.05 m) penetrated by 55% / 13% of its
// displacement with cells of 2h at t / H = 0.5 / 0.78 and was solved twice, at 1.07 once; the free
// plate (t = 0.02 m) by 69% / 59% at 0.25 / 0.37 and solved twice, at 0.86 once. Thicker bodies are
// left to the penetration test after the solve (refine_unresolved_contact), which also catches narrow
// contact zones (the gasket's rims: solved twice at t / H = 1.04 and 1.77, the roller's strip at 9.3).
constexpr double kThinBodyCells = 0.8;

// What "auto" found thin (the note for the run), or nullopt: start on cells of 2h.
std::optional<std::string> thin_body_over_contact(const Scene& scene, const FaceThicknessOnce& measured) {
  if (!scene.cell_size_auto || !scene.cell_size_relative || scene.contact.empty()) return std::nullopt;
  const FaceThickness& thickness = measured.get();
  const double cell = scene.cell_size * thickness.element_size;
  if (!(thickness.median < kThinBodyCells * cell)) return std::nullopt;
  const std::string unit = std::string(" ") + unit_labels(scene.output.units).length;
  return "the body is " + number(thickness.median, 3) + unit + " thick over most of Γc (the median), less than " +
         number(kThinBodyCells, 2) + " of a cell of " + number(scene.cell_size, 2) + "h (H = " + number(cell, 3) +
         unit + "), inside which it would bend and penetrate: cells of " + number(kRefinedCellSize, 2) +
         "h from the start";
}

// The stage times of `other` added into `into`'s, stage by stage (a benchmark's total is the user's wait),
// but for the reference factorizations (solver.reference_factorization): they are the yardstick of
// one factorization of K, which summed over two solves would halve every ratio (until 2026-12-05 the
// "benchmark:" line of a scene solved twice divided by two of them).
void add_stage_seconds(std::vector<std::pair<std::string, double>>& into,
                       const std::vector<std::pair<std::string, double>>& other) {
  for (const auto& [name, seconds] : other) {
    if (name.rfind("reference_", 0) == 0 || name.rfind("cpu_reference_", 0) == 0) continue;
    const auto it = std::find_if(into.begin(), into.end(), [&](const auto& stage) { return stage.first == name; });
    if (it != into.end())
      it->second += seconds;
    else
      into.emplace_back(name, seconds);
  }
}

}  // namespace

FinerAnswer compare_finer_answer(const SolveResult& first, const SolveResult& finer) {
  return {finer.penetration_ratio < first.penetration_ratio, first.converged && !finer.converged,
          dual_ill_conditioned(finer) && !dual_ill_conditioned(first)};
}

namespace {

SolveResult refine_unresolved_contact(const Scene& scene, const Mesh& mesh, const FaceThicknessOnce& thickness,
                                      const ProgressCallback& on_step, Progress& report, SolveResult first,
                                      KeptFactor& first_factor) {
  PartitionRefinement refinement;
  refinement.tried = true;
  refinement.first_cell_size = first.cell_size;
  refinement.first_penetration_ratio = first.penetration_ratio;
  for (const auto& stage : first.seconds) refinement.first_seconds += stage.second;
  const std::string finer_cells = "cells of " + number(kRefinedCellSize, 2) + "h";
  // Over ten times the deformation (a prescribed approach moving the body rigidly while no cell touches:
  // 4.5e13 times on a V-shaped sole), the ratio says little: the depth instead.
  const std::string depth = first.penetration_ratio <= 10
                                ? share_of_displacement(first.penetration_ratio) + " the largest displacement"
                                : number(first.wn_plus_inf, 3) + ", over ten times the body's own deformation";
  const std::string was = "cells of " + cell_sizes(first) + " (2h) let nodes penetrate by " + depth;
  report.stage("contact zone unresolved: " + was + "; solving again with " + finer_cells +
               " (contact.cell_size = \"auto\")");
  const Scene finer = with_refined_cells(scene);
  std::optional<SolveResult> second;
  try {
    RunningStage stage;
    second = solve_stages(finer, mesh, thickness, on_step, report, stage, &first_factor);
  } catch (const InputError& e) {  // e.g. the finer partition violates (5.1)
    refinement.outcome = finer_cells + " were refused (" + e.what() + "): the answer is the 2h one";
  } catch (const std::bad_alloc&) {
    refinement.outcome = finer_cells + " did not fit in memory: the answer is the 2h one";
  }
  first_factor.factor.reset();
  if (second) {
    refinement.reused_factor = second->factor_reused;
    const FinerAnswer verdict = compare_finer_answer(first, *second);
    refinement.kept_finer = verdict.better();
    refinement.outcome =
        "with " + finer_cells + " (" + cell_sizes(*second) +
        (second->factor_reused ? ", Q formed from the first solve's factor of K" : "") + "): nodes penetrate by " +
        share_of_displacement(second->penetration_ratio) + " the largest displacement" +
        (refinement.kept_finer        ? ", the answer given"
         : !verdict.penetrates_less   ? ", no better: the answer is the 2h one"
         : verdict.loses_conditioning ? " but its Q is ill-conditioned (cond(Q) ≈ " +
                                            number(second->stability_condition, 3) + "): the answer is the 2h one"
                                      : " but that solve ended with " + second->status + ": the answer is the 2h one");
  }
  // The console's last stage lines are the second solve's: say which answer is given (a helper read
  // "585 cells, 1 755 multipliers" above an answer on the 347 cells of 2h).
  report.stage("contact.cell_size = \"auto\": " + refinement.outcome);
  refinement.outcome = was + "; " + refinement.outcome;
  SolveResult kept = refinement.kept_finer ? std::move(*second) : std::move(first);
  if (second) add_stage_seconds(kept.seconds, refinement.kept_finer ? first.seconds : second->seconds);
  kept.notes.push_back("contact.cell_size = \"auto\": " + refinement.outcome);
  kept.refinement = std::move(refinement);
  return kept;
}

// contact.cell_size = "auto", a body held by contact alone refused with cells of 2h because its
// contact zone spans too few of them (ContactZoneTooCoarse): solved again with cells of 1.5h, which
// rescues a zone about two cells of 2h across (a soft ball resting on two cells,
// tests/held_by_contact_cells.py); refused there too, the refusal names both cell sizes.
SolveResult refine_refused_cells(const Scene& scene, const Mesh& mesh, const FaceThicknessOnce& thickness,
                                 const ProgressCallback& on_step, Progress& report, const std::string& refusal,
                                 double refused_seconds, KeptFactor& first_factor) {
  const std::string finer_cells = "cells of " + number(kRefinedCellSize, 2) + "h";
  report.stage("cells of 2h refused: " + refusal + "; solving again with " + finer_cells +
               " (contact.cell_size = \"auto\")");
  const Scene finer = with_refined_cells(scene);
  SolveResult res;
  try {
    RunningStage stage;
    res = solve_stages(finer, mesh, thickness, on_step, report, stage, &first_factor);
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + " (with " + finer_cells +
                     "; contact.cell_size = \"auto\" tried them after cells of 2h were refused too)");
  }
  PartitionRefinement& refinement = res.refinement;
  refinement.tried = true;
  refinement.first_cell_size = std::numeric_limits<double>::quiet_NaN();  // refused before its answer
  refinement.first_penetration_ratio = std::numeric_limits<double>::quiet_NaN();
  refinement.first_seconds = refused_seconds;
  refinement.kept_finer = true;
  refinement.reused_factor = res.factor_reused;
  refinement.outcome = "cells of 2h were refused (" + refusal + "); with " + finer_cells + " (" + cell_sizes(res) +
                       "): the answer given";
  res.notes.push_back("contact.cell_size = \"auto\": " + refinement.outcome);
  return res;
}

}  // namespace

DualPlan plan_dual(const Scene& scene, const Mesh& mesh, const FaceThicknessOnce& thickness) {
  reserve_blas_buffers();  // as the solve does: the memory it plans with is what the solve will see
  SolveResult res;
  res.dofs = make_dof_map(mesh, scene.clamped, scene.displacements);
  const std::optional<std::string> thin = thin_body_over_contact(scene, thickness);  // the cells the solve starts on
  const ContactOperator op = contact_stage(thin ? with_refined_cells(scene) : scene, mesh, res);
  const DenseDualMemory memory = dense_dual_memory(scene.solver.qp, op.rows());
  const DualMethod resolved = resolved_dual_method(scene.solver.dual_method);
  require_backend(scene, resolved);
  std::optional<DualMethod> chosen = dual_method_for_memory(scene.solver.dual_method, resolved, memory.fits());
  DualPlan plan;
  // MUMPS analyses on its ranks, and contactlast orders K's contact dofs last: no prediction of theirs.
  const bool predicted = chosen && !is_mumps(*chosen) && *chosen != DualMethod::ContactLast;
  const Eigen::SparseMatrix<double> K =
      predicted ? assemble_stiffness(mesh, res.dofs, tet_materials(scene, mesh)) : Eigen::SparseMatrix<double>();
  std::optional<FactorPrediction> augmented;  // the factor with the multipliers, where it was predicted
  if (augmented_may_crowd(scene, chosen, memory)) {
    augmented = SparseCholesky::predict(K, &op.B);
    if (const std::optional<std::string> crowded = augmented_crowds(*augmented, op.rows(), memory)) {
      plan.route_reason = *crowded;
      chosen = DualMethod::MatrixFree;
    }
  }
  plan.cells = op.r;
  plan.multipliers = op.rows();
  plan.cell_size = res.cell_size;
  if (res.partition.graded) plan.cell_sizes = describe_cell_sizes(res.partition);
  plan.regions = res.partition.regions;
  plan.dense_bytes = memory.bytes;
  plan.available_bytes = memory.available;
  plan.method = chosen ? std::string(name_of(*chosen, kDualMethodNames)) : std::string();
  plan.thin_body = thin.value_or("");
  plan.warnings = res.warnings;
  if (predicted) {
    const bool with_multipliers = *chosen == DualMethod::Augmented;  // blocksolve and matrix_free factor K alone
    const FactorPrediction factor =
        with_multipliers && augmented ? *augmented : SparseCholesky::predict(K, with_multipliers ? &op.B : nullptr);
    const DualMemoryNeed dual = *chosen == DualMethod::MatrixFree ? matrix_free_need(scene.solver.qp, op.rows())
                                                                  : DualMemoryNeed{memory.bytes, false};
    plan.factor_nonzeros = factor.factor_nonzeros;
    plan.factor_flops = factor.flops;
    plan.run_bytes = run_need_bytes(factor.factor_nonzeros, dual, memory.available);
    std::string tight = require_factor_fits(factor.factor_nonzeros, dual);  // the solve's refusal, or
    if (!tight.empty()) plan.warnings.push_back(std::move(tight));          // its warning
  }
  return plan;
}

SolveResult solve_scene(const Scene& scene, const Mesh& mesh, const ProgressCallback& on_step, Progress* progress) {
  if (std::any_of(scene.tractions.begin(), scene.tractions.end(),
                  [](const Traction& t) { return t.total_force.has_value(); })) {
    Scene resolved = scene;  // [[boundary.force]] as tractions, in the mesh's own frame
    resolve_total_forces(resolved, mesh);
    return solve_scene(resolved, mesh, on_step, progress);
  }
  if (!scene.foundation.is_identity()) {  // a tilted or shifted foundation: solve in its frame
    const PlaneFrameProblem local = to_plane_frame(scene, mesh);
    SolveResult res = solve_scene(local.scene, local.mesh, on_step, progress);
    result_to_user_frame(scene.foundation, res);
    return res;
  }
  Progress silent;
  Progress& report = progress ? *progress : silent;
  RunningStage stage;
  stage.holds = "K for " + count(3 * static_cast<long long>(mesh.nodes.size())) + " unknowns";
  try {
    reserve_blas_buffers();  // under ulimit -v: before anything large, so that the memory checks see them
    const auto start = std::chrono::steady_clock::now();
    const FaceThicknessOnce thickness(mesh, scene.contact);  // measured once, where first needed
    const std::optional<std::string> thin = thin_body_over_contact(scene, thickness);
    // The measurement "auto" made, counted in the contact stage (the solves' own stages start after it).
    const std::vector<std::pair<std::string, double>> measured = {
        {"contact", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}};
    if (thin) {
      report.stage("contact.cell_size = \"auto\": " + *thin);
      SolveResult res = solve_stages(with_refined_cells(scene), mesh, thickness, on_step, report, stage);
      add_stage_seconds(res.seconds, measured);
      res.refinement.started_finer = true;
      res.refinement.outcome = *thin;
      res.notes.push_back("contact.cell_size = \"auto\": " + *thin);
      return res;
    }
    SolveResult res;
    KeptFactor kept;  // the factor of K, for a second solve with cells of 1.5h
    try {
      res = solve_stages(scene, mesh, thickness, on_step, report, stage, scene.cell_size_auto ? &kept : nullptr);
    } catch (const ContactZoneTooCoarse& e) {
      if (!scene.cell_size_auto) throw;
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      res = refine_refused_cells(scene, mesh, thickness, on_step, report, e.what(), seconds, kept);
      time_kept_reference(scene, kept, res);
      return res;
    }
    if (scene.cell_size_auto && unresolved(res))
      res = refine_unresolved_contact(scene, mesh, thickness, on_step, report, std::move(res), kept);
    add_stage_seconds(res.seconds, measured);
    time_kept_reference(scene, kept, res);
    return res;
  } catch (const std::bad_alloc&) {
    const bool dual_sized = stage.name == "contact" || stage.name == "stability check" || stage.name == "dual solve";
    throw InputError("out of memory in the " + stage.name + " stage, which holds " + stage.holds + "; " +
                     gib(static_cast<double>(available_memory_bytes())) + " are available to this process now; " +
                     (dual_sized ? "use a larger contact.cell_size (H: fewer multipliers)"
                                 : "use a coarser mesh (mesh.n, or the mesh parameters' h)") +
                     " or a machine with more memory");
  }
}

}  // namespace contact3d
