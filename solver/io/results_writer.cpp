#include "io/results_writer.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>

#include "base/errors.hpp"
#include "base/multiplier_layout.hpp"
#include "io/atomic_file.hpp"
#include "io/json_writer.hpp"
#include "io/pvd_writer.hpp"
#include "io/settings_json.hpp"
#include "io/vtu_format.hpp"
#include "io/vtu_writer.hpp"
#include "model/solution_fields.hpp"

namespace contact3d {
namespace {

// One entry per Tresca (or frictionless) solve: the fixed-point history, or, when the scene needed
// a single solve (constant or no friction), that solve as step 1 with err = 0 (nothing depends on
// φ, so the first solve is the fixed point). Keeps history.csv, err_history, the progress lines,
// fixed_point_iterations and the steps of solution.pvd the same length.
std::vector<FixedPointStep> solve_history(const SolveResult& res) {
  if (!res.fixed_point.history.empty() || res.steps.empty()) return res.fixed_point.history;
  double seconds = 0;
  for (const auto& [stage, sec] : res.seconds)
    if (stage == "dual_solve") seconds = sec;
  return {FixedPointStep{1, 0.0, res.qp_iterations, res.n_mult, seconds}};
}

bool has_friction(const SolveResult& res) { return contact3d::has_friction(res.n_cells, res.lambda); }

void write_cells_vtu(const std::filesystem::path& file, const SolveResult& res, vtu::Encoding encoding) {
  std::vector<Eigen::Vector2d> pts;
  std::vector<std::size_t> offsets, owner;
  for (std::size_t i = 0; i < res.partition.cells.size(); ++i)
    for (const auto& piece : res.partition.cells[i].pieces) {
      for (const auto& v : piece.polygon) pts.push_back(v.xy);
      offsets.push_back(pts.size());
      owner.push_back(i);
    }
  const MultiplierLayout at{res.n_cells, has_friction(res)};
  const bool fr = at.with_friction;
  const std::vector<int> cs = cell_status(res.n_cells, res.lambda, res.radius);
  write_file(file, [&](std::ostream& out) {
    vtu::write_piece(out, encoding, pts.size(), owner.size(), [&](vtu::PieceWriter& piece) {
      piece.xml("      <CellData Scalars=\"lambda_n\">\n");
      piece.data_array(
          "cell", 1, owner.size(), [&](std::size_t k, int) { return owner[k]; }, vtu::Type::Int64);
      piece.data_array("lambda_n", 1, owner.size(), [&](std::size_t k, int) { return res.lambda[owner[k]]; });
      piece.data_array("lambda_t", 3, owner.size(), [&](std::size_t k, int c) {
        const int cell = static_cast<int>(owner[k]);
        return !fr || c == 2 ? 0.0 : res.lambda[c == 0 ? at.t1(cell) : at.t2(cell)];
      });
      piece.data_array("radius", 1, owner.size(), [&](std::size_t k, int) { return fr ? res.radius[owner[k]] : 0.0; });
      piece.data_array(
          "contact_status", 1, owner.size(), [&](std::size_t k, int) { return cs[owner[k]]; }, vtu::Type::Int32);
      piece.xml("      </CellData>\n      <Points>\n");
      piece.data_array("Points", 3, pts.size(), [&](std::size_t i, int c) {  // the cells lie in the foundation plane
        return res.frame.to_global_point(Eigen::Vector3d(pts[i].x(), pts[i].y(), 0.0))[c];
      });
      piece.xml("      </Points>\n      <Cells>\n");
      piece.data_array(
          "connectivity", 1, pts.size(), [](std::size_t k, int) { return k; }, vtu::Type::Int64);
      piece.data_array(
          "offsets", 1, offsets.size(), [&](std::size_t e, int) { return offsets[e]; }, vtu::Type::Int64);
      piece.data_array(
          "types", 1, owner.size(), [](std::size_t, int) { return 7; }, vtu::Type::UInt8);
      piece.xml("      </Cells>\n");
    });
  });
}

void write_vector(JsonWriter& j, const char* key, const Eigen::Vector3d& v) {
  j.begin_array(key).element(v.x()).element(v.y()).element(v.z()).end_array();
}

// "forces": the resultants on the body (N, global x, y, z) and their balance.
void write_forces(JsonWriter& j, const ResultantForces& f) {
  j.begin_object("forces");
  write_vector(j, "applied", f.applied);
  write_vector(j, "contact", f.contact);
  write_vector(j, "contact_at_held_nodes", f.contact_at_held_nodes);  // in the reactions, not in "contact"
  j.begin_array("reactions");
  for (const auto& r : f.reactions) {
    j.begin_object().value("condition", r.condition);
    write_vector(j, "force", r.force);
    j.end_object();
  }
  j.end_array();
  j.value("balance", f.balance);
  j.end_object();
}

// The problem's sizes: mesh, unknowns, contact face and its cells.
void write_sizes(JsonWriter& j, const Mesh& mesh, const SolveResult& res, const RunInfo& info) {
  j.value("mesh", info.mesh_description);
  j.value("n_nodes", static_cast<long long>(mesh.nodes.size()))
      .value("n_tets", static_cast<long long>(mesh.tets.size()));
  j.value("n_primal", res.n_primal).value("n_dual", res.n_dual);
  j.value("n_contact_nodes", static_cast<long long>(res.face.nodes.size())).value("n_cells", res.n_cells);
  j.value("contact_h", res.face.h)
      .value("cell_size", res.cell_size)
      .value("cells_merged", res.partition.merged_slivers);
  j.value("cells_split", res.partition.split_cells).value("cells_merged_for_stability", res.partition.stability_merges);
  j.value("contact_regions", res.partition.regions);
  j.value("cells_graded", res.partition.graded);
  if (res.partition.graded) {  // the rectangles follow the contact mesh (contact/grid_boxes.hpp): their sides
    for (const auto& [key, sides] : {std::pair{"cell_sides_smallest", res.partition.smallest_box},
                                     std::pair{"cell_sides_largest", res.partition.largest_box}})
      j.begin_array(key).element(sides.x()).element(sides.y()).end_array();
  }
}

// What the solve cost: fixed-point steps, the paper's n_mult and the QP's own counts.
void write_work(JsonWriter& j, const SolveResult& res) {
  j.value("fixed_point_iterations", std::max(1, res.fixed_point.iterations()));
  j.value("n_mult", res.n_mult)
      .value("qp_iterations", res.qp_iterations)
      .value("qp_newton_steps", res.qp_newton_steps)
      .value("qp_newton_steps_bordered", res.qp_bordered_newton_steps)
      .value("qp_newton_steps_feasible", res.qp_feasible_newton_steps)
      .value("qp_rounding_stops", res.qp_rounding_stops)
      .value("qp_bordered_factor_in_double", res.qp_bordered_factor_in_double)
      .value("qp_single_products", res.qp_single_products)
      .value("qp_coarse_products", res.qp_coarse_products);
  j.value("schur_method", res.schur_method).value("qp_method", res.qp_method);
}

// Where the factorization ran: the backend, its ranks and their peak memory, the BLAS threads.
void write_backend(JsonWriter& j, const SolveResult& res, const RunInfo& info) {
  j.begin_object("backend").value("name", res.backend);
  // ranks: those that factor (1 for CHOLMOD on rank 0, the others waiting); processes: all mpirun started,
  // one peak memory each.
  j.value("ranks", res.ranks).value("processes", static_cast<int>(res.peak_memory_per_rank_mib.size()));
  j.value("near_null_space", res.near_null_space).begin_array("peak_memory_mib_per_rank");
  for (double mib : res.peak_memory_per_rank_mib) j.element(mib);
  j.end_array();
  // OpenBLAS's threads (blas_threads.hpp): fitted to the cores other processes left idle, or under
  // mpirun to this machine's cores shared among its ranks
  j.begin_object("blas_threads").value("threads", info.blas.threads).value("before", info.blas.before);
  j.value("cores", info.blas.cores).value("user_set", info.blas.user_set);
  if (info.blas.busy_elsewhere >= 0) j.value("busy_cores_elsewhere", info.blas.busy_elsewhere);
  if (info.blas.ranks_on_machine > 1) j.value("ranks_on_machine", info.blas.ranks_on_machine);
  j.end_object().end_object();
}

// The law as solved, its parameters included where the scene left them to their defaults (law = "ramp"
// alone takes the paper's (6.1) values, which summary.json did not say).
void write_friction_law(JsonWriter& j, const FrictionLaw& law) {
  j.begin_object("friction_law").value("kind", law.name());
  if (law.kind == FrictionLaw::Kind::Constant) j.value("value", law.value);
  if (law.kind == FrictionLaw::Kind::Ramp)
    j.value("high", law.high).value("low", law.low).value("t0", law.t0).value("param", law.param);
  if (law.kind == FrictionLaw::Kind::Table) {
    j.begin_array("points");
    for (const auto& [t, f] : law.points) j.begin_array().element(t).element(f).end_array();
    j.end_array();
  }
  j.end_object();
}

// How the solve ended: the friction model, the last QP, err per step and the fixed point's bound.
void write_convergence(JsonWriter& j, const Scene& scene, const SolveResult& res) {
  j.value("friction_model",
          scene.frictionless() ? std::string("none") : name_of(scene.friction_model, kFrictionModelNames));
  write_friction_law(j, scene.law);
  j.value("qp_last_status", to_string(res.last_qp.status))
      .value("qp_last_projected_gradient", res.last_qp.projected_gradient);
  j.begin_array("err_history");
  for (const auto& s : solve_history(res)) j.element(s.err);
  j.end_array();
  if (!res.fixed_point.history.empty()) {  // how far the answer may be from the fixed point of (5.7)
    const FixedPointResult& fp = res.fixed_point;
    j.begin_object("fixed_point");
    j.value("contraction_factor", fp.contraction_factor);  // null before three steps
    j.value("contracted", fp.contraction_factor < 1);      // q < 1 observed over the last steps
    j.value("distance_bound", fp.distance_bound);          // q/(1 − q)·err, an estimate; null when q >= 1
    j.value("qp_tolerance_tightenings", fp.qp_tolerance_tightenings);
    j.value("plain_fallback_step", fp.plain_fallback_step);  // 0: the variant never fell back to plain steps
    j.value("mixed_steps", fp.mixed_steps);                  // iterates from the accelerated variant's tail mixing
    j.value("newton_steps", fp.newton_steps);                // iterates from its Newton steps on the slip
    j.value("predicted_steps", fp.predicted_steps);          // iterates from the fixed point of G's prediction
    j.value("final_qp_rtol", fp.history.back().qp_rtol);
    j.value("hint", fp.hint);
    j.end_object();
  }
}

// The answer on the contact face: penetration, conditioning, warnings and notes, forces and areas.
void write_contact(JsonWriter& j, const SolveResult& res) {
  j.value("wn_plus_L2", res.wn_plus_L2).value("wn_plus_inf", res.wn_plus_inf);
  j.value("stability_condition_estimate", res.stability_condition);
  if (res.stability_condition_scaled > 0) j.value("stability_condition_scaled", res.stability_condition_scaled);
  j.value("factor_nonzeros", res.factor_nonzeros);
  j.begin_array("warnings");
  for (const auto& w : res.warnings) j.element(w);
  j.end_array();
  j.begin_array("notes");
  for (const auto& n : res.notes) j.element(n);
  j.end_array();
  j.value("step_solve_fraction", res.step_solve_fraction);
  const ContactResultants cr = contact_resultants(res, final_state(res));
  // ∫λ over the cells in the plane's frame: the normal force on the body, and (t1, t2) = ∫λ_t,
  // minus the friction force on the body (forces.contact has the whole force on the body, user axes).
  j.begin_object("contact_force").value("normal", cr.normal).value("t1", cr.t1).value("t2", cr.t2);
  j.value("tangential", std::hypot(cr.t1, cr.t2)).end_object();
  if (has_friction(res))
    j.value("friction_torque", cr.friction_torque);  // foundation's friction on the body about Γc's centroid, along n
  if (res.friction_hold_share >= 0)  // the loads' share of friction's hold along a slide or turn only it holds
    j.value("friction_hold_share", res.friction_hold_share);
  j.value("max_penetration", res.wn_plus_inf);          // max nodal (w_n − d)⁺ on Γc
  j.value("penetration_ratio", res.penetration_ratio);  // max_penetration / the largest nodal displacement
  j.value("open_gap_ratio", res.open_gap_ratio);        // the largest gap under pressed cells, the same way
  j.value("largest_strain", res.largest_strain);        // largest principal strain in absolute value (warned above 10%)
  if (const PartitionRefinement& pr = res.refinement; pr.started_finer) {  // "auto" found the body thin
    j.begin_object("partition_refinement").value("started_finer", true).value("outcome", pr.outcome).end_object();
  } else if (pr.tried) {  // contact.cell_size = "auto" solved twice
    j.begin_object("partition_refinement").value("first_cell_size", pr.first_cell_size);
    j.value("first_penetration_ratio", pr.first_penetration_ratio).value("first_seconds", pr.first_seconds);
    j.value("kept_finer", pr.kept_finer).value("reused_factor", pr.reused_factor);
    j.value("outcome", pr.outcome).end_object();
  }
  j.value("friction_where_separated_area", res.friction_where_separated_area);  // Tresca's bound where λ_n = 0
  {  // areas of the cells by status (in the plane; the cells' own areas)
    const double no_friction = std::numeric_limits<double>::quiet_NaN();  // null: no stick/slip without friction
    j.begin_object("contact_area").value("in_contact", cr.area[kStick] + cr.area[kSlip]);
    j.value("stick", has_friction(res) ? cr.area[kStick] : no_friction);
    j.value("slip", has_friction(res) ? cr.area[kSlip] : no_friction);
    j.value("separated", cr.area[kSeparated]).end_object();
  }
}

// The units of the reports, the steps written and the encoding of the VTU files.
void write_units(JsonWriter& j, const Scene& scene, const Mesh& mesh, const SolveResult& res) {
  const UnitLabels units = unit_labels(scene.output.units);
  j.begin_object("units").value("system", name_of(scene.output.units, kUnitSystemNames)).value("length", units.length);
  j.value("force", units.force).value("stress", units.stress).end_object();
  j.value("output_steps", name_of(steps_written(res) ? StepOutput::All : StepOutput::Final, kStepOutputNames));
  const bool binary = binary_vtu(scene.output.vtu, mesh.nodes.size());
  j.value("output_vtu", name_of(binary ? VtuFormat::Binary : VtuFormat::Ascii, kVtuFormatNames));
}

// The KKT residuals of the answer (every run writes them).
void write_kkt(JsonWriter& j, const Scene& scene, const SolveResult& res) {
  j.begin_object("kkt");
  j.value("equilibrium", res.kkt.equilibrium).value("normal_feasibility", res.kkt.normal_feasibility);
  j.value("normal_complementarity", res.kkt.normal_complementarity).value("disc_feasibility", res.kkt.disc_feasibility);
  j.value("slip_alignment", res.kkt.slip_alignment).value("normal_cellwise", res.kkt.normal_cellwise);
  j.value("friction_cellwise", res.kkt.friction_cellwise).value("projected_gradient", res.last_qp.projected_gradient);
  if (scene.coulomb()) j.value("coulomb_relation", res.coulomb_relation);  // max |c − F̄λ_n| / max c
  j.end_object();
  j.value("kkt_worst_cell", res.kkt.worst_cell);  // beside kkt, whose entries are all residuals
}

}  // namespace

void write_summary_json(const std::filesystem::path& file, const Scene& scene, const Mesh& mesh, const SolveResult& res,
                        const RunInfo& info, double output_seconds) {
  write_file(file, [&](std::ostream& out) {
    JsonWriter j(out);
    j.begin_object();
    j.value("status", res.status).value("converged", res.converged);
    j.begin_object("run").value("contact3d_version", info.version).value("scene_file", info.scene_file);
    j.value("mesh_override", info.mesh_override).value("working_directory", info.working_directory);
    j.begin_array("overrides");
    for (const std::string& o : info.overrides) j.element(o);
    j.end_array().end_object();
    write_sizes(j, mesh, res, info);
    write_work(j, res);
    write_backend(j, res, info);
    write_convergence(j, scene, res);
    write_contact(j, res);
    write_units(j, scene, mesh, res);
    write_forces(j, res.forces);
    j.begin_object("time_s");
    j.value("total", info.total_seconds).value("mesh", info.mesh_seconds);
    for (const auto& [stage, sec] : res.seconds) j.value(stage, sec);
    j.value("output", output_seconds);
    j.end_object();
    write_kkt(j, scene, res);
    write_solver_settings(j, scene.solver);
    j.value("scene", scene.echo);
    j.end_object();
    out << "\n";
  });
}

void write_results(const std::filesystem::path& dir, const Scene& scene, const Mesh& mesh, const SolveResult& res,
                   const RunInfo& info) {
  const auto start = std::chrono::steady_clock::now();
  const ContactNodeFields nf = contact_node_fields(mesh, scene, res, final_state(res));
  write_file(dir / "contact_nodes.csv", [&](std::ostream& out) {
    out << "node,x,y,z,u1,u2,u3,wn,wt_norm,F,pressure,status\n";
    for (int v : res.face.nodes) {
      const auto& x = mesh.nodes[v];
      const double u1 = res.u[3 * v], u2 = res.u[3 * v + 1], u3 = res.u[3 * v + 2];
      const Eigen::Vector3d local = res.frame.to_local(res.u.segment<3>(3 * v));  // wn, wt in the plane's frame
      out << mesh.node_tags[v] << ',' << x.x() << ',' << x.y() << ',' << x.z() << ',' << u1 << ',' << u2 << ',' << u3
          << ',' << -local.z() << ',' << local.head<2>().norm() << ',' << nf.friction[v] << ',' << nf.pressure[v] << ','
          << nf.status[v] << '\n';
    }
  });
  write_file(dir / "contact_cells.csv", [&](std::ostream& out) {
    out << "cell,xmin,xmax,ymin,ymax,area,lambda_n,lambda_t1,lambda_t2,radius\n";
    const MultiplierLayout at{res.n_cells, has_friction(res)};
    for (int i = 0; i < at.r; ++i) {
      const auto& c = res.partition.cells[i];
      const bool fr = at.with_friction;
      out << i << ',' << c.lo.x() << ',' << c.hi.x() << ',' << c.lo.y() << ',' << c.hi.y() << ',' << c.area << ','
          << res.lambda[at.normal(i)] << ',' << (fr ? res.lambda[at.t1(i)] : 0.0) << ','
          << (fr ? res.lambda[at.t2(i)] : 0.0) << ',' << (fr ? res.radius[i] : 0.0) << '\n';
    }
  });
  write_file(dir / "history.csv", [&](std::ostream& out) {
    out << "k,err,qp_iterations,n_mult,seconds,update,qp_rtol\n";
    for (const auto& s : solve_history(res))
      out << s.k << ',' << s.err << ',' << s.qp_iterations << ',' << s.n_mult << ',' << s.seconds << ','
          << name_of(s.update, kFixedPointUpdateNames) << ',' << s.qp_rtol << '\n';
  });
  const TetMaterials materials = tet_materials(scene, mesh);
  const VtuContext ctx{scene, mesh, res, materials};
  write_state_vtus(dir / "body.vtu", dir / "contact.vtu", ctx, final_state(res));
  if (res.n_cells > 0) write_cells_vtu(dir / "contact_cells.vtu", res, ctx.encoding);
  write_solution_collection(dir, ctx);
  const std::chrono::duration<double> output = std::chrono::steady_clock::now() - start;
  write_summary_json(dir / "summary.json", scene, mesh, res, info, output.count());
}

}  // namespace contact3d
