// contact3d command line:
//   contact3d solve SCENE.toml [--mesh FILE.msh] [--set key=value]... [--out DIR] [--quiet]
//   contact3d mesh brick --n N [-o FILE.msh]      (the paper's five-tet brick, MSH 4.1)
//   contact3d check SCENE.toml [--mesh FILE.msh]  (validate scene and mesh without solving)
// Exit codes: 0 solved and converged, 1 solved but not converged, 2 bad input or failure.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "base/memory.hpp"
#include "contact/face_dofs.hpp"
#include "contact/partition.hpp"
#include "distributed/backend.hpp"
#include "io/atomic_file.hpp"
#include "io/results_writer.hpp"
#include "io/run_folder.hpp"
#include "linalg/blas_threads.hpp"
#include "mesh/brick_generator.hpp"
#include "mesh/msh_writer.hpp"
#include "mesh/read_mesh.hpp"
#include "model/contact_solver.hpp"
#include "model/held_by_contact.hpp"
#include "model/input_warnings.hpp"
#include "model/mesh_source.hpp"
#include "model/plane_frame.hpp"
#include "model/scene.hpp"
#include "model/solution_fields.hpp"

namespace fs = std::filesystem;
using namespace contact3d;

namespace {

// A console line on stdout. Where the reader has gone (SIGPIPE is ignored) the write fails and the
// line is dropped: fmt::print would throw and end a solve whose results still go to its folder.
template <class... Args>
void say(fmt::format_string<Args...> format, Args&&... args) {
  const std::string text = fmt::format(format, std::forward<Args>(args)...);
  static_cast<void>(std::fwrite(text.data(), 1, text.size(), stdout));
}

struct SolveArgs {
  std::string scene, mesh, out;
  std::string keep_mesh;  // check: where to keep the mesh it made (empty: a temporary file, removed)
  std::vector<std::string> sets;
  bool quiet = false;
  int ranks = 1;                       // MPI ranks (the distributed build under mpirun)
  BlasThreadChoice blas_under_mpirun;  // ranks > 1: the threads the Session gave rank 0's OpenBLAS
};

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

fs::path output_dir_for(const Scene& scene, const SolveArgs& args) {
  if (!args.out.empty()) return args.out;
  if (!scene.output.dir.empty()) return scene.output.dir;
  return fs::path("results/runs") / fs::path(args.scene).stem();
}

Mesh scene_mesh(const Scene& scene, const std::string& mesh_override, const fs::path& work_dir,
                std::string& description) {
  if (!mesh_override.empty()) {
    description = mesh_override;
    return read_mesh_file(mesh_override);
  }
  const auto& src = scene.mesh;
  description = !src.generator.empty() ? src.generator + " n=" + std::to_string(src.n)
                : !src.geo.empty()     ? src.geo.string() + " (gmsh) -> " + (work_dir / "mesh.msh").string()
                : !src.edp.empty()     ? src.edp.string() + " (FreeFEM) -> " + (work_dir / "mesh.mesh").string()
                                       : src.file.string();
  return load_scene_mesh(src, work_dir);
}

// The meshers' files in the output folder that this run did not write — an earlier run's gmsh mesh.msh
// and gmsh.log beside a solve of a mesh file — would sit beside its results as if they were its mesh:
// removed where the mesher's log marks them as a run's (a user's own mesh.msh, with no gmsh.log beside
// it or with a gmsh.log of their own, stays), unless the mesh is the one this run read.
void remove_other_runs_mesh_files(const fs::path& out, const Scene& scene, const std::string& mesh_override) {
  const fs::path read = !mesh_override.empty() ? fs::path(mesh_override) : scene.mesh.file;
  const bool by_gmsh = mesh_override.empty() && !scene.mesh.geo.empty();
  const bool by_freefem = mesh_override.empty() && !scene.mesh.edp.empty();
  for (const auto& [mesh_name, log_name, ours] :
       {std::tuple{"mesh.msh", "gmsh.log", by_gmsh}, {"mesh.mesh", "freefem.log", by_freefem}}) {
    std::error_code ec;
    if (ours || !fs::exists(out / log_name, ec) || !written_by_a_run(out / log_name)) continue;
    fs::remove(out / log_name, ec);
    if (!(!read.empty() && fs::equivalent(out / mesh_name, read, ec))) fs::remove(out / mesh_name, ec);
  }
}

// Γu, when named, must hold at least one triangle, and so must every displacement group (a named
// but empty group would silently prescribe nothing).
void require_constrained_triangles(const Scene& scene, const Mesh& mesh) {
  std::size_t n = 0;
  std::string names;
  for (const auto& g : scene.clamped) {
    n += mesh.triangles_of_group(g).size();
    names += (names.empty() ? "'" : ", '") + g + "'";
  }
  if (!scene.clamped.empty() && n == 0)
    throw InputError("boundary.clamped: the group(s) " + names + " hold no triangles, so Γu is empty");
  for (const auto& d : scene.displacements)
    if (mesh.triangles_of_group(d.group).empty())
      throw InputError("boundary.displacement: the group '" + d.group + "' holds no triangles");
}

// With solver.reference_factorization: the yardstick of the benchmarks on the console. The solve's
// stages (assembly to postprocess, as pipeline/bench.py sums them) against one factorization of K
// timed in the same process; the printed total also holds the mesh and these reference factorizations.
void print_benchmark_ratio(const SolveResult& res, double mesh_seconds) {
  static const std::vector<std::string> kSolveStages = {"assembly",  "contact",    "factorization", "dual",
                                                        "stability", "dual_solve", "postprocess"};
  double solve = 0, reference = 0, reference_nd = 0, yardsticks = 0;
  for (const auto& [stage, seconds] : res.seconds) {
    if (std::find(kSolveStages.begin(), kSolveStages.end(), stage) != kSolveStages.end()) solve += seconds;
    if (stage == "reference_factorization") reference += seconds;
    if (stage == "reference_factorization_nd") reference_nd += seconds;
    if (stage.rfind("reference_", 0) == 0) yardsticks += seconds;
  }
  if (reference <= 0) return;
  say("benchmark: solve stages {:.2f} s = {:.2f} x one factorization of K ({:.2f} s; {:.2f} s with this solver's "
      "ordering); the total also holds the mesh ({:.2f} s) and these reference factorizations ({:.2f} s)\n",
      solve, solve / reference, reference, reference_nd, mesh_seconds, yardsticks);
}

// The numbers engineers look for, on the CLI's last lines (all of them also in summary.json).
void print_engineering_summary(const Scene& scene, const SolveResult& res) {
  const UnitLabels u = unit_labels(scene.output.units);
  if (res.n_cells > 0) {
    const ContactResultants cr = contact_resultants(res, final_state(res));
    const bool friction = has_friction(res.n_cells, res.lambda);
    say("contact: normal force {:.4g} {}, tangential {:.4g} {}; area in contact {:.4g} {}²", cr.normal, u.force,
        std::hypot(cr.t1, cr.t2), u.force, cr.area[kStick] + cr.area[kSlip], u.length);
    if (friction)
      say(" (stick {:.4g}, slip {:.4g}); friction torque {:.4g} {} {}", cr.area[kStick], cr.area[kSlip],
          cr.friction_torque, u.force, u.length);
    say("; max penetration {:.3g} {}\n", res.wn_plus_inf, u.length);
    const Eigen::Vector3d& held = res.forces.contact_at_held_nodes;
    if (held.norm() > 1e-9 * (res.forces.contact + held).norm())
      say("  of which ({:.4g}, {:.4g}, {:.4g}) {} at contact nodes with prescribed components, counted in "
          "the reactions below\n",
          held.x(), held.y(), held.z(), u.force);
  }
  for (const auto& r : res.forces.reactions)
    say("reaction on {}: ({:.4g}, {:.4g}, {:.4g}) {}\n", r.condition, r.force.x(), r.force.y(), r.force.z(), u.force);
}

// What reading a mesh changed in it: solve's mesh line and notes, check's notes.
std::vector<std::string> what_reading_changed(const Mesh& mesh) {
  std::vector<std::string> read_as;
  if (mesh.read_by_corner_nodes) read_as.emplace_back("second-order elements read by their corner nodes: P1");
  if (mesh.reoriented_mirrored)
    read_as.emplace_back("every tetrahedron negatively oriented, a mirrored mesh: reoriented");
  return read_as;
}

int run_solve(const SolveArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const CpuSnapshot start = cpu_snapshot();  // what other processes do while the scene and mesh load
  // The folder is claimed before anything can fail, so a failed rerun never leaves the previous
  // run's summary.json looking like this run's result.
  std::optional<RunFolder> folder;
  if (!args.out.empty()) folder.emplace(args.out, "contact3d solve " + args.scene);
  const Scene scene = load_scene(args.scene, args.sets);
  const fs::path out = output_dir_for(scene, args);
  if (!folder) folder.emplace(out, "contact3d solve " + args.scene);
  RunInfo info;
  info.version = CONTACT3D_VERSION;
  std::error_code cwd_error;
  info.working_directory = fs::current_path(cwd_error).string();
  info.scene_file = fs::absolute(args.scene, cwd_error).lexically_normal().string();
  if (!args.mesh.empty()) info.mesh_override = fs::absolute(args.mesh, cwd_error).lexically_normal().string();
  info.overrides = args.sets;
  // Stage lines and the QP's heartbeat (every 2 s on a terminal, every 10 s into a log file).
  auto print_line = [](const std::string& line) {
    say("{}\n", line);
    std::fflush(stdout);
  };
  Progress stages = args.quiet ? Progress() : Progress(print_line, print_line, ::isatty(STDOUT_FILENO) ? 2.0 : 10.0);
  const Mesh mesh = [&] {
    const Progress::Watch meshing(stages, "mesh");  // gmsh or FreeFEM may take minutes
    return scene_mesh(scene, args.mesh, out, info.mesh_description);
  }();
  remove_other_runs_mesh_files(out, scene, args.mesh);
  info.mesh_seconds = since(t0);
  require_constrained_triangles(scene, mesh);
  // Under mpirun the Session gave each rank its share of the machine's cores.
  info.blas = args.ranks == 1 ? fit_blas_threads_to_idle_cores(start) : args.blas_under_mpirun;
  if (!args.quiet && info.blas.threads < info.blas.before)
    say("BLAS threads: {} of {} ({})\n", info.blas.threads, info.blas.before,
        info.blas.busy_elsewhere >= 0
            ? fmt::format("other processes keep {:.1f} of the {} cores busy", info.blas.busy_elsewhere, info.blas.cores)
            : fmt::format("this rank's share of the {} cores among the {} ranks", info.blas.cores, args.ranks));
  // What reading changed, on the mesh line and in summary.json's "mesh".
  const std::vector<std::string> read_as = what_reading_changed(mesh);
  std::string reading_notes;
  for (const std::string& r : read_as) reading_notes += " (" + r + ")";
  info.mesh_description += reading_notes;
  if (!args.quiet)
    say("mesh: {} nodes, {} tets, {} boundary triangles{} ({:.2f} s)\n", mesh.nodes.size(), mesh.tets.size(),
        mesh.triangles.size(), reading_notes, info.mesh_seconds);
  auto progress = [&](const FixedPointStep& s) {
    if (!args.quiet)
      say("k={:3d}  err={:.3e}  qp_iterations={:6d}  n_mult={:7d}  {:.3f} s  ({})\n", s.k, s.err, s.qp_iterations,
          s.n_mult, s.seconds, name_of(s.update, kFixedPointUpdateNames));
    std::fflush(stdout);
  };
  SolveResult res = solve_scene(scene, mesh, progress, &stages);
  // What reading changed is the run's to say too (summary.json's notes, the report), not only its mesh line.
  for (auto r = read_as.rbegin(); r != read_as.rend(); ++r) res.notes.insert(res.notes.begin(), "the mesh: " + *r);
  info.total_seconds = since(t0);
  write_results(out, scene, mesh, res, info);
  folder->finish(res.converged ? std::string()
                               : res.status + (res.fixed_point.hint.empty() ? "" : "; " + res.fixed_point.hint));
  if (!args.quiet) {
    say("{}: n_p={} n_d={} it={} n_mult={} |wn+|_L2={:.2e} |wn+|_inf={:.2e} kkt_max={:.1e} total {:.2f} s\n",
        res.status, res.n_primal, res.n_dual, std::max(1, res.fixed_point.iterations()), res.n_mult, res.wn_plus_L2,
        res.wn_plus_inf, res.kkt.max(), info.total_seconds);
    print_engineering_summary(scene, res);
    if (scene.solver.reference_factorization) print_benchmark_ratio(res, info.mesh_seconds);
    say("results in {}\n", out.string());
  }
  for (const auto& w : res.warnings) std::cerr << "warning: " << w << "\n";
  if (!res.converged && !res.fixed_point.hint.empty()) std::cerr << "hint: " << res.fixed_point.hint << "\n";
  return res.converged ? 0 : 1;
}

// The dual problem a solve would form: its size, and the route solver.schur takes for it here.
void print_dual_plan(const DualPlan& plan, const std::string& length_unit) {
  const std::string available =
      plan.available_bytes > 0 ? bytes_text(plan.available_bytes) + " available" : "available memory unknown";
  std::string route = "solver.schur = \"" + plan.method + "\"";
  if (plan.method.empty())
    route =
        "does not fit, and the scene names a dense solver.schur: the solve would be refused (use a larger "
        "contact.cell_size, or solver.schur = \"matrix_free\")";
  else if (plan.method == "matrix_free")
    route += " (" + (plan.route_reason.empty() ? std::string() : plan.route_reason + "; ") +
             "Q not formed: each QP product through the factor of K, slow; a larger contact.cell_size keeps the "
             "dense Q)";
  const std::string sizes =
      (plan.cell_sizes.empty() ? fmt::format("H = {:.4g} {}", plan.cell_size, length_unit) : plan.cell_sizes) +
      describe_regions(plan.regions);
  if (!plan.thin_body.empty()) say("contact.cell_size = \"auto\": {}\n", plan.thin_body);
  for (const auto& w : plan.warnings) std::cerr << "warning: " << w << "\n";
  say("dual: {} cells ({}), {} multipliers; the dense Q with its working copies {}, {}: {}\n", plan.cells, sizes,
      plan.multipliers, bytes_text(plan.dense_bytes), available, route);
  if (plan.factor_nonzeros > 0)
    say("factor: nnz(L) = {:.3g} ({}), {:.3g} GFlop (CHOLMOD's symbolic analysis); the solve needs about {} beyond "
        "the mesh and K\n",
        plan.factor_nonzeros, bytes_text(8 * plan.factor_nonzeros), plan.factor_flops / 1e9,
        bytes_text(plan.run_bytes));
}

// The contact face's heights above the foundation plane (its initial gap d): a face resting on the
// plane, or one that starts above it all over — a mesh in CAD coordinates without contact.plane_point.
std::string describe_initial_gap(const ContactFace& face, const std::string& length_unit) {
  double lowest = INFINITY, highest = 0;
  for (const int v : face.nodes) {
    lowest = std::min(lowest, face.gap[static_cast<std::size_t>(v)]);
    highest = std::max(highest, face.gap[static_cast<std::size_t>(v)]);
  }
  if (highest == 0) return "on the foundation plane (no initial gap)";
  const std::string range = fmt::format("initial gap {:.4g} to {:.4g} {}", lowest, highest, length_unit);
  // A face that touches up to rounding (a cylinder's tangent line meshed: 4.9e-11 m on a 0.1 m face)
  // rests on the plane.
  constexpr double kTouching = 1e-6;  // of the face's extent
  return lowest > kTouching * (face.hi - face.lo).maxCoeff()
             ? range + " (the whole face starts above the plane: is contact.plane_point where the body rests?)"
             : range;
}

// The error of a failed command on stderr, after what it printed on stdout so far (buffered: `check`'s
// lines would otherwise run into the message, "… tetrahedraerror: …"); the exit code of bad input.
int print_error(const std::string& message) {
  std::fflush(stdout);
  std::cout.flush();
  std::cerr << "error: " << message << "\n";
  return 2;
}

// check's mesh, made by gmsh or FreeFEM in a scratch folder removed at exit: said so in its description
// (a helper looked for the file it named), or copied to `keep` for a solve with --mesh (the foot's 54 s
// of meshing were paid again by the solve).
std::string kept_or_temporary_mesh(std::string description, const fs::path& work, const std::string& keep) {
  fs::path made;
  for (const char* name : {"mesh.msh", "mesh.mesh"})
    if (fs::exists(work / name)) made = work / name;
  const std::string scratch = made.string();
  const std::size_t at = scratch.empty() ? std::string::npos : description.find(scratch);
  if (!keep.empty()) {
    if (made.empty())
      throw InputError("check --keep-mesh: the scene's mesh (" + description +
                       ") is not one check makes with gmsh or FreeFEM; the solve reads or builds it as it is");
    std::error_code ec;
    fs::copy_file(made, keep, fs::copy_options::overwrite_existing, ec);
    if (ec) throw InputError("check --keep-mesh: cannot write '" + keep + "': " + ec.message());
    if (at != std::string::npos) description.replace(at, scratch.size(), keep);
    return description + " (kept: solve it with --mesh " + keep + ")";
  }
  if (at != std::string::npos)
    description.replace(at, scratch.size(), "a temporary file, removed at exit (check --keep-mesh FILE keeps it)");
  return description;
}

// `check`, with `step` naming what it does at each moment (for run_check's out-of-memory message).
int check_scene(const SolveArgs& args, std::string& step) {
  const Scene user_scene = load_scene(args.scene, args.sets);
  const fs::path work = fs::temp_directory_path() / ("contact3d_check_" + std::to_string(::getpid()));
  struct RemoveOnExit {  // gmsh's scratch folder goes away even when meshing throws
    fs::path dir;
    ~RemoveOnExit() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cleanup{work};
  std::string description;
  const Mesh user_mesh = scene_mesh(user_scene, args.mesh, work, description);
  description = kept_or_temporary_mesh(description, work, args.keep_mesh);
  say("scene: {}\nmesh: {} — {} nodes, {} tets, {} boundary triangles\n", args.scene, description,
      user_mesh.nodes.size(), user_mesh.tets.size(), user_mesh.triangles.size());
  say("physical groups: {}\n", user_mesh.describe_groups());
  // Each group as a scene names it (a label or an unnamed gmsh group by its number), with its size.
  for (const auto& g : user_mesh.groups) {
    std::size_t count = 0;
    if (g.dim == 2) {
      for (int t : user_mesh.triangle_group) count += (t == g.tag);
    } else {
      count = user_mesh.tets_of_group(g.tag).size();
    }
    const std::string name = g.name.empty() ? std::to_string(g.tag) : g.name;
    say("  {:<16} dim {}  {} {}\n", "\"" + name + "\"", g.dim, count, g.dim == 2 ? "triangles" : "tetrahedra");
  }
  step = "checking the mesh and the loads (" + count(static_cast<long long>(user_mesh.nodes.size())) + " nodes, " +
         count(static_cast<long long>(user_mesh.tets.size())) + " tetrahedra)";
  // A tilted or shifted foundation: the checks below see the problem in the plane's frame, as the solve does.
  Scene resolved_scene = user_scene;  // [[boundary.force]] as tractions, in the mesh's own frame
  resolve_total_forces(resolved_scene, user_mesh);
  const PlaneFrameProblem local = to_plane_frame(resolved_scene, user_mesh);
  const Scene& scene = local.scene;
  const Mesh& mesh = local.mesh;
  check_coordinates_in_range(mesh);
  check_tet_orientation(mesh);
  check_mesh_meaning(mesh, mesh_roles(scene));
  // Quality: worst ratio of inradius-like measure (volume / longest edge³), scaled to 1 for a regular tet.
  double worst = 1e300;
  for (const auto& t : mesh.tets) {
    TetCoords x{mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]};
    double h = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) h = std::max(h, (x[a] - x[b]).norm());
    worst = std::min(worst, tet_volume(x) / (h * h * h) * 6 * std::sqrt(2.0));
  }
  say("worst tet quality (volume / longest edge³, 1 = regular): {:.3g}\n", worst);
  require_constrained_triangles(scene, mesh);
  for (const auto& tr : scene.tractions) mesh.triangles_of_group(tr.group);
  const DofMap dofs = make_dof_map(mesh, scene.clamped, scene.displacements);
  // Motions nothing prescribed holds are the contact's to hold (refused without a contact face).
  const ContactHeldMotions held = contact_held_motions(mesh, dofs, !scene.contact.empty(), scene.user_frame);
  if (held.count())
    say("held by contact alone: {}{}\n", held.describe(),
        !held.in_plane_count() ? std::string()
        : scene.frictionless() ? "; in the foundation's plane by nothing (the contact is frictionless: the "
                                 "loads along them must balance by themselves): " +
                                     held.describe_in_plane()
                               : "; in the foundation's plane by friction alone: " + held.describe_in_plane());
  // The loads as the solve checks them before factoring K, the lift's after the contact face's check.
  const TetMaterials materials = tet_materials(scene, mesh);
  const Eigen::VectorXd applied = assemble_load(mesh, dofs, scene.tractions, tet_body_forces(scene, mesh));
  const Eigen::VectorXd f = applied + assemble_lift(mesh, dofs, materials);
  if (held.in_plane_count() && scene.frictionless()) require_in_plane_balance(held, f, scene.how_to_add_friction());
  SolveResult warned;  // the warnings a solve gives on its input, before it starts
  const FaceThicknessOnce thickness(mesh, scene.contact);
  warn_about_inputs(scene, mesh, dofs, materials, thickness, warned);
  for (const auto& w : warned.warnings) std::cerr << "warning: " << w << "\n";
  // The notes on the input that summary.json carries after a solve.
  for (const auto& r : what_reading_changed(user_mesh)) say("note: the mesh: {}\n", r);
  for (const auto& n : warned.notes) say("note: {}\n", n);
  if (!scene.contact.empty()) {
    const ContactFace face = make_contact_face(mesh, scene.contact, dofs);
    if (held.count()) {
      require_free_parts_on_contact_face(held, FaceDofs(face, dofs, mesh.nodes.size()).dofs);
      require_loads_press_onto_plane(held, f, applied);
    }
    const std::string length = unit_labels(scene.output.units).length;
    say("contact face: {} triangles, {} contact nodes, area {:.6g} {}², h = {:.4g} {}; {}\n", face.triangles.size(),
        face.nodes.size(), face.area, length, face.h, length, describe_initial_gap(face, length));
    if (face.held_triangles > 0)
      say("  and {} triangles (area {:.6g} {}²) whose every node is clamped or prescribed: left to that "
          "condition\n",
          face.held_triangles, face.held_area, length);
    step = "planning the dual: the contact partition, K for " + count(static_cast<long long>(3 * mesh.nodes.size())) +
           " unknowns at most and the symbolic analysis of its factor";
    print_dual_plan(plan_dual(scene, mesh, thickness), length);
  }
  say("ok: scene and mesh are consistent (stability (5.1) is checked when solving)\n");
  return 0;
}

// `check` under a memory limit it cannot meet says where, as the solve does (it said only "out of memory").
int run_check(const SolveArgs& args) {
  std::string step = "reading the scene and its mesh";
  try {
    return check_scene(args, step);
  } catch (const std::bad_alloc&) {
    throw InputError("out of memory while " + step + "; " + bytes_text(static_cast<double>(available_memory_bytes())) +
                     " are available to this process now: use a coarser mesh or a machine with more memory");
  }
}

// The processes an MPI launcher started this one among (Open MPI's mpirun, MPICH's and Intel's
// Hydra), and this one's rank; 1 and 0 without a launcher.
std::pair<long, long> launched_processes() {
  for (const auto& [size, rank] : {std::pair{"OMPI_COMM_WORLD_SIZE", "OMPI_COMM_WORLD_RANK"}, {"PMI_SIZE", "PMI_RANK"}})
    if (const char* n = std::getenv(size)) {
      const char* r = std::getenv(rank);
      return {std::max(1L, std::atol(n)), r ? std::atol(r) : 0L};
    }
  return {1, 0};
}

// Whether the parent process is an MPI launcher's (not a script it started, which may run serial
// solves of its own: the launcher's variables reach those too).
bool started_by_launcher() {
  std::ifstream in("/proc/" + std::to_string(getppid()) + "/comm");
  std::string parent;
  std::getline(in, parent);
  for (const char* launcher : {"mpirun", "mpiexec", "orterun", "orted", "prterun", "prted", "hydra_pmi_proxy"})
    if (parent == launcher) return true;
  return false;
}

// The serial build started by mpirun with several processes would run the whole solve once per
// process, all writing the same folder: refused (exit 2), said once, by the first process.
bool serial_build_under_mpirun() {
  const auto [processes, rank] = launched_processes();
  if (distributed::available() || processes <= 1 || !started_by_launcher()) return false;
  if (rank == 0)
    std::cerr << "error: this contact3d is the serial build, started by an MPI launcher with " << processes
              << " processes: each would solve the whole scene alone. Run it without mpirun, or build the "
                 "distributed one (`make build-mpi`) and run `mpirun -np P build-mpi/contact3d solve SCENE`\n";
  return true;
}

// SIGINT, SIGTERM, SIGHUP: a line on stderr, then the signal's own end (exit status 128 + the signal,
// as without the handler). The output folder keeps its RUNNING marker and no summary.json — not an
// answer — and the next solve into it clears it; a stopped run said nothing of that. The handler makes
// only async-signal-safe calls (unlink of the result file being written, write, raise; SA_RESETHAND
// restores the default action first).
extern "C" void say_stopped_and_end(int sig) {
  static const char kInterrupted[] =
      "\ncontact3d: interrupted (SIGINT): stopped; the output folder holds no answer (its RUNNING file says so)\n";
  static const char kTerminated[] =
      "\ncontact3d: terminated (SIGTERM): stopped; the output folder holds no answer (its RUNNING file says so)\n";
  static const char kHungUp[] =
      "\ncontact3d: hung up (SIGHUP): stopped; the output folder holds no answer (its RUNNING file says so)\n";
  const char* text = sig == SIGINT ? kInterrupted : sig == SIGTERM ? kTerminated : kHungUp;
  const std::size_t size = sig == SIGINT ? sizeof kInterrupted : sig == SIGTERM ? sizeof kTerminated : sizeof kHungUp;
  remove_partial_file_for_signal();
  [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, text, size - 1);
  std::raise(sig);
}

void say_why_when_stopped() {
  struct sigaction action {};
  action.sa_handler = say_stopped_and_end;
  action.sa_flags = SA_RESETHAND;
  sigemptyset(&action.sa_mask);
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction before {};
    // A signal the parent made the process ignore (nohup's SIGHUP, a background job's SIGINT) stays ignored.
    if (sigaction(sig, nullptr, &before) == 0 && before.sa_handler == SIG_IGN) continue;
    sigaction(sig, &action, nullptr);
  }
}

// An output path given empty (`--out "$OUTDIR"` with the variable unset) is refused: it fell back to the
// default folder or file without a word (a helper's find).
const CLI::Validator kNotEmpty(
    [](const std::string& value) {
      return value.empty() ? std::string("an empty path (is the variable it came from unset?)") : std::string();
    },
    "PATH");

// The command line on rank 0 (the only process of the serial build): its exit code.
int run_command_line(int argc, char** argv, const distributed::Session& session) {
  CLI::App app{"contact3d: 3D contact with solution-dependent Tresca friction (Haslinger & Ligurský 2009)"};
  app.set_version_flag("--version", std::string("contact3d ") + CONTACT3D_VERSION);
  app.require_subcommand(1);
  SolveArgs args;
  auto* solve = app.add_subcommand("solve", "solve a scene");
  solve->add_option("scene", args.scene, "scene file (TOML)")->required();
  solve->add_option("--mesh", args.mesh,
                    "use this mesh file (.msh, or FreeFEM's .mesh/.meshb) instead of the scene's mesh");
  solve->add_option("--set", args.sets, "override a scene key, e.g. --set friction.param=2e4");
  solve->add_option("--out", args.out, "output folder")->check(kNotEmpty);
  solve->add_flag("--quiet", args.quiet, "print nothing on stdout (errors, warnings and hints still go to stderr)");
  solve->footer("Solver choices (scene keys, also for --set): solver.qp = " + names_list(kQpVariantNames) +
                "; solver.qp_scaling = " + names_list(kQpScalingNames) + "; solver.qp_precision = " +
                names_list(kQpPrecisionNames) + "; solver.fixed_point = " + names_list(kFixedPointVariantNames) +
                "; solver.schur = " + names_list(kDualMethodNames) +
                ". summary.json records the resolved settings under \"settings\".");
  auto* check = app.add_subcommand("check", "validate a scene and its mesh without solving");
  check->add_option("scene", args.scene, "scene file (TOML)")->required();
  check->add_option("--mesh", args.mesh,
                    "use this mesh file (.msh, or FreeFEM's .mesh/.meshb) instead of the scene's mesh");
  check->add_option("--set", args.sets, "override a scene key");
  check
      ->add_option("--keep-mesh", args.keep_mesh,
                   "keep the mesh check makes from the scene's geometry in this file, for solve --mesh")
      ->check(kNotEmpty);
  auto* mesh_cmd = app.add_subcommand("mesh", "write a built-in mesh");
  std::string kind, out_file;
  int n = 4;
  mesh_cmd->add_option("kind", kind, "brick: the paper's five-tet brick")->required()->check(CLI::IsMember({"brick"}));
  mesh_cmd->add_option("--n", n, "cubes per unit length (3n x n x n cubes)")->capture_default_str();
  mesh_cmd->add_option("-o,--output", out_file, "output .msh (default brick_n<N>.msh)")->check(kNotEmpty);

  // A full disk or a file-size limit must fail a write (an error naming the file), not kill the process;
  // a closed stdout (`contact3d solve … | head -1`) drops the console's lines, not the run (say()).
  std::signal(SIGXFSZ, SIG_IGN);
  std::signal(SIGPIPE, SIG_IGN);
  say_why_when_stopped();
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) { return app.exit(e); } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // CLI11 checks required arguments before unexpected ones: `solve --frobnicate` would be told that
    // the scene is missing. The unexpected argument is the user's mistake; it is named first.
    const std::vector<std::string> unexpected = app.remaining(true);
    if (dynamic_cast<const CLI::RequiredError*>(&e) != nullptr && !unexpected.empty()) {
      std::cerr << "error: " << CLI::ExtrasError(unexpected).what() << "\n"
                << "run 'contact3d --help' (or 'contact3d solve --help') for the usage\n";
      return 2;
    }
    std::cerr << "error: " << e.what() << "\n"
              << "run 'contact3d --help' (or 'contact3d solve --help') for the usage\n";
    return 2;
  }
  try {
    args.ranks = session.ranks();
    args.blas_under_mpirun = session.blas_threads();
    if (*solve) return run_solve(args);
    if (*check) return run_check(args);
    if (*mesh_cmd) {
      const Mesh m = make_paper_brick(BrickSize{n});
      if (out_file.empty()) out_file = "brick_n" + std::to_string(n) + ".msh";
      write_msh41(m, out_file);
      say("wrote {} ({} nodes, {} tets)\n", out_file, m.nodes.size(), m.tets.size());
      return 0;
    }
  } catch (const InputError& e) { return print_error(e.what()); } catch (const std::bad_alloc&) {
    return print_error("out of memory (try a coarser mesh)");
  } catch (const std::exception& e) { return print_error(e.what()); }
  return 2;
}

// Standard streams the caller closed (`contact3d solve … >&- 2>&-`) opened on /dev/null: the first files the
// run opened took their numbers, and the console's report went into the folder's lock file, its warnings
// into a result file being written (a helper's run: RUNNING and every result file opened as descriptor 2).
void open_closed_standard_streams() {
  for (int fd = 0; fd <= 2; ++fd) {
    if (fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
    const int opened = open("/dev/null", fd == 0 ? O_RDONLY : O_WRONLY);  // the lowest free number: fd
    if (opened != fd && opened >= 0) close(opened);
  }
}

// The process ends here, its streams flushed, without the libraries' finalizers: OpenBLAS's joins its
// worker threads, and a worker that could not map its work space (under a low ulimit -v, from the
// library's start) spins forever, so a run refused with exit 2 never ended (a helper's 100 MB limit).
[[noreturn]] void end_process(int code) {
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::_Exit(code);
}

int run_session(int argc, char** argv) {
  // The distributed build: every rank but 0 only serves rank 0's factorization and solves, and ends
  // with rank 0's exit code (a bad input: 2 on every rank, not 2 on rank 0 and 0 on the others).
  distributed::Session session(argc, argv);
  if (!session.is_root()) return session.serve();
  const int code = run_command_line(argc, argv, session);
  std::fflush(stdout);  // before the other ranks end: mpirun may stop the job at a non-zero exit
  session.finish(code);
  return code;
}  // the session's end finalizes MPI

// The restart through /proc/self/exe (restart_with_huge_pages) leaves the process named "exe" in ps, top
// and pgrep, where a helper could not find a running solve: named again after the program's file (at
// most 15 characters, the kernel's limit).
void name_process_after(const char* program) {
  const std::string name = std::filesystem::path(program ? program : "contact3d").filename().string().substr(0, 15);
  prctl(PR_SET_NAME, name.c_str(), 0, 0, 0);
}

}  // namespace

int main(int argc, char** argv) {
  open_closed_standard_streams();
  if (serial_build_under_mpirun()) end_process(2);
  restart_with_huge_pages(argv);  // returns in the restarted process (base/memory.hpp)
  name_process_after(argv[0]);
  keep_freed_memory();  // stages reuse the pages earlier stages freed (base/memory.hpp)
  end_process(run_session(argc, argv));
}
