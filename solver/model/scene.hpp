// Scene: everything a solve needs, read from a TOML file (pipeline/scenes/*.toml) with
// optional `--set key=value` overrides. Every option is declared once here with its default
// and unit; unknown keys, wrong types and non-finite numbers are InputErrors naming the key.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "contact/foundation_frame.hpp"
#include "fem/assembly.hpp"
#include "fem/dof_map.hpp"
#include "fem/elasticity.hpp"
#include "friction/fixed_point.hpp"
#include "friction/friction_law.hpp"
#include "linalg/dual_problem.hpp"
#include "mesh/mesh_checks.hpp"
#include "qp/dual_qp_solver.hpp"

namespace contact3d {

struct MeshSource {
  std::filesystem::path file;  // an .msh file, or
  std::filesystem::path geo;   // a gmsh .geo script meshed with -setnumber parameters, or
  std::filesystem::path edp;   // a FreeFEM script run as `FreeFem++ -nw edp -out F -<key> <value>...`, or
  std::map<std::string, double> parameters;
  std::string generator;  // "paper_brick": the built-in five-tet brick
  int n = 4;              // generator resolution
  // A .geo or .edp script is code. Untrusted (the default), it may not run programs (gmsh's
  // SystemCall, Shell, OnelabRun, ...; FreeFEM's exec, system) nor include files outside its own
  // folder; `trusted = true` in [mesh] lifts both.
  bool trusted = false;
};

inline constexpr NameTable<DualMethod, 7> kDualMethodNames{{{DualMethod::Auto, "auto"},
                                                            {DualMethod::BlockSolve, "blocksolve"},
                                                            {DualMethod::ContactLast, "contactlast"},
                                                            {DualMethod::Augmented, "augmented"},
                                                            {DualMethod::Mumps, "mumps"},
                                                            {DualMethod::MumpsPetsc, "mumps_petsc"},
                                                            {DualMethod::MatrixFree, "matrix_free"}}};

// [solver]: every option with its default; the scene key is the field name unless noted.
struct SolverSettings {
  double qp_rtol = 1e-6;                              // ‖g̃‖ <= qp_rtol ‖h‖ (the paper's criterion)
  double fixed_point_tol = FixedPointSettings{}.tol;  // err(k) <= this (the paper's 1e-4)
  int fixed_point_max_iter = FixedPointSettings{}.max_iterations;
  // qp (variant: "auto" MPGP switching to Newton steps where it is slow, "mpgp" the paper's
  // algorithm, "mpgp_projcg", "ssn"), qp_scaling ("jacobi": a diagonal scaling that keeps
  // half-lines and discs; "none": the paper's plain MPGP), qp_precision ("auto": MPGP's products
  // through a single-precision Q from kMixedPrecisionMinSize multipliers on, "double", "mixed";
  // the tolerance is always checked in double), qp_newton_systems ("auto": Newton steps solve
  // through the stability check's factor of Q where that is cheaper, "reduced": they factor their
  // reduced matrix; NewtonSystems), qp_cg_preconditioner ("lumped": the matrix-free route's Newton
  // steps precondition their CG by FETI's lumped preconditioner, "diagonal"; CgPreconditioner),
  // qp_max_iterations.
  QpSettings qp;
  // "accelerated" (default: plain while it contracts fast, Aitken's relaxation once it does not),
  // "plain" (the paper's (5.7)), "aitken" (relaxation from the start) or "anderson" (FixedPointVariant).
  FixedPointVariant fixed_point = FixedPointSettings{}.variant;
  int anderson_depth = FixedPointSettings{}.anderson_depth;
  // "accelerated": the tail begins at err < fixed_point_tail_err (0: never), where Newton steps on the
  // slip (fixed_point_newton) or Anderson mixing replace the relaxation (FixedPointSettings).
  double fixed_point_tail_err = FixedPointSettings{}.tail_err;
  bool fixed_point_newton = FixedPointSettings{}.newton;
  // "accelerated": once it relaxes, predicted steps (the fixed point of G's prediction from the QP's
  // sensitivity to the radii, the law exact) where they converge (FixedPointSettings::predicted_steps).
  bool fixed_point_prediction = FixedPointSettings{}.predicted_steps;
  // Fixed-point step k solves its QP to min(qp_rtol, qp_rtol_per_err · err(k−1)); 0: at qp_rtol.
  double qp_rtol_per_err = FixedPointSettings{}.qp_rtol_per_err;
  DualMethod dual_method = DualMethod::Auto;  // key `schur`: how Q = 𝔹K⁻¹𝔹ᵀ is formed (DualMethod)
  bool inexact_fixed_point = FixedPointSettings{}.inexact;  // QP tolerance tied to err(k) in early fixed-point steps
  bool reference_factorization =
      false;  // also time plain factorizations of K (time_s.reference_factorization: CHOLMOD's ordering; _nd: ours)
  // The MUMPS backend's out-of-core mode (schur = "mumps"): each rank writes its part of the factor
  // to files in this directory (relative to the scene file; on every machine) and reads it back in
  // each solve, so that it holds only the fronts being worked on. "" (default): in memory.
  std::filesystem::path out_of_core_dir;
};

// [output]: where the run is written and what it keeps.
// steps: "all" writes the body and the contact face after every solve (a ParaView time step each;
// one extra back substitution per step), "final" only the answer; "auto" (default) is "all" while
// nodes × steps stays within kStepOutputAutoNodeSteps and "final" beyond (the body's ASCII VTU takes
// about 0.8 kB per node, so a long fixed point on a small mesh would otherwise write hundreds of MB).
enum class StepOutput { Auto, All, Final };
inline constexpr NameTable<StepOutput, 3> kStepOutputNames{
    {{StepOutput::Auto, "auto"}, {StepOutput::All, "all"}, {StepOutput::Final, "final"}}};
inline constexpr std::size_t kStepOutputAutoNodeSteps = 300000;  // about 250 MB of step files
inline StepOutput resolved(StepOutput steps, std::size_t n_nodes, std::size_t n_steps) {
  if (steps != StepOutput::Auto) return steps;
  return n_nodes * n_steps <= kStepOutputAutoNodeSteps ? StepOutput::All : StepOutput::Final;
}
// vtu: the encoding of body.vtu, contact.vtu (and every step's) and contact_cells.vtu: "ascii" (numbers as text,
// readable by any script), "binary" (raw values after the XML in an <AppendedData> section, as
// ParaView and VTK read them: 30% smaller, written 4 times faster), "auto" (default):
// ascii up to kVtuAutoAsciiNodes mesh nodes (about 100 MB of body.vtu), binary beyond.
enum class VtuFormat { Auto, Ascii, Binary };
inline constexpr NameTable<VtuFormat, 3> kVtuFormatNames{
    {{VtuFormat::Auto, "auto"}, {VtuFormat::Ascii, "ascii"}, {VtuFormat::Binary, "binary"}}};
inline constexpr std::size_t kVtuAutoAsciiNodes = 100000;
inline bool binary_vtu(VtuFormat format, std::size_t n_nodes) {
  return format == VtuFormat::Binary || (format == VtuFormat::Auto && n_nodes > kVtuAutoAsciiNodes);
}
// units: the labels of the figures, report and VTU files. The solver is unit-agnostic: the scene's
// lengths, forces and moduli must be given in this consistent system.
enum class UnitSystem { MetreNewtonPascal, MillimetreNewtonMegapascal, MetreKilonewtonKilopascal };
inline constexpr NameTable<UnitSystem, 3> kUnitSystemNames{{{UnitSystem::MetreNewtonPascal, "m-N-Pa"},
                                                            {UnitSystem::MillimetreNewtonMegapascal, "mm-N-MPa"},
                                                            {UnitSystem::MetreKilonewtonKilopascal, "m-kN-kPa"}}};
struct UnitLabels {
  const char *length, *force, *stress;
};
UnitLabels unit_labels(UnitSystem units);
double pascal_per_stress_unit(UnitSystem units);  // 1, 1e6 or 1e3

struct OutputSettings {
  std::filesystem::path dir;  // default results/runs/<scene name> (or --out)
  StepOutput steps = StepOutput::Auto;
  VtuFormat vtu = VtuFormat::Auto;
  UnitSystem units = UnitSystem::MetreNewtonPascal;
};

// [[material.region]]: the material of one volume (3-D) group's tetrahedra.
struct MaterialRegion {
  std::string group;
  Material material;
  std::optional<Eigen::Vector3d> body_force;  // N/m³; [material]'s body_force where not given
};

struct Scene {
  std::filesystem::path source;  // the scene file (relative paths are resolved against its folder)
  MeshSource mesh;
  Material material;  // [material]: every tetrahedron not in a region
  std::vector<MaterialRegion> regions;
  Eigen::Vector3d body_force = Eigen::Vector3d::Zero();  // N/m³
  std::vector<std::string> clamped, contact;             // clamped: u = 0 on the group (Γu)
  std::vector<PrescribedDisplacement> displacements;     // [[boundary.displacement]]: group, any of x, y, z (m)
  std::vector<Traction> tractions;  // [[boundary.traction]] (value, gradient) and [[boundary.pressure]]
  FrictionModel friction_model = FrictionModel::Tresca;  // friction.model
  double slip_bound = 0;                                 // g, Pa (Tresca only)
  FrictionLaw law;
  // [friction] keys given that the chosen law does not read (accepted so that `--set friction.law=…`
  // switches laws without editing the scene; a note says so)
  std::vector<std::string> friction_keys_not_read;
  double cell_size = 2;  // H: a length in m, or a multiple of h when relative
  bool cell_size_relative = true;
  // contact.cell_size = "auto" (the default): cells of 2h, and the scene is solved again with cells of
  // 1.5h when 2h leaves the contact zone unresolved (model/contact_solver.hpp, refine_unresolved_contact);
  // a body thinner than a cell of 2h over Γc starts on cells of 1.5h (thin_body_over_contact).
  bool cell_size_auto = true;
  // [contact] plane_point (m, default origin) and plane_normal (towards the body, default +z).
  FoundationFrame foundation;
  // Not an option: where a solve runs in the plane's frame (plane_frame.hpp), the user's frame, for
  // messages that name points and directions; the identity otherwise.
  FoundationFrame user_frame;
  SolverSettings solver;
  OutputSettings output;
  std::string echo;  // the scene as solved, TOML text (overrides applied)

  bool frictionless() const {
    return law.kind == FrictionLaw::Kind::None || (friction_model == FrictionModel::Tresca && slip_bound == 0) ||
           (law.kind == FrictionLaw::Kind::Constant && law.value == 0);
  }
  // For a frictionless scene: which key makes it so and what to set instead (friction.value = 0 under
  // Coulomb's model was told to add friction.slip_bound, which that model does not read).
  std::string how_to_add_friction() const {
    if (law.kind == FrictionLaw::Kind::None)
      return "add friction (friction.law, e.g. \"constant\" with friction.value)";
    if (law.kind == FrictionLaw::Kind::Constant && law.value == 0) return "give friction.value a coefficient above 0";
    return "give friction.slip_bound, Tresca's bound, a value above 0 (or friction.model = \"coulomb\")";
  }
  bool coulomb() const { return friction_model == FrictionModel::Coulomb && !frictionless(); }
  // Successive approximations are needed: F depends on the slip, or the bound is λ_n (Coulomb).
  bool needs_fixed_point() const { return !frictionless() && (law.depends_on_slip() || coulomb()); }
};

// [[boundary.force]] entries made tractions: each resultant spread uniformly over its group's area
// (value = F / area, in the mesh's own frame, before to_plane_frame). Groups missing from the mesh are
// left to check_mesh_meaning; a group of zero area is refused.
void resolve_total_forces(Scene& scene, const Mesh& mesh);

// The roles the scene gives the mesh's groups (for check_mesh_meaning).
MeshRoles mesh_roles(const Scene& scene);

// The material of every tetrahedron: regions by volume group, the rest [material]. Throws
// InputError for a region whose group is missing, not a volume group, or overlapping another.
TetMaterials tet_materials(const Scene& scene, const Mesh& mesh);
// Each tetrahedron's body force: [material]'s, or its region's where that region gives one.
BodyForce tet_body_forces(const Scene& scene, const Mesh& mesh);

// Reads the scene; `overrides` are "dotted.key=value" strings (value in TOML syntax; a bare
// word is taken as a string).
Scene load_scene(const std::filesystem::path& path, const std::vector<std::string>& overrides = {});
Scene parse_scene_text(const std::string& toml_text, const std::filesystem::path& base_dir,
                       const std::vector<std::string>& overrides = {});

}  // namespace contact3d
