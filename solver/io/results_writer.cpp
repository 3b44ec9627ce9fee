#include "io/results_writer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <fstream>
#include <stdexcept>

#include "fem/elasticity.hpp"
#include "base/errors.hpp"
#include "io/atomic_file.hpp"
#include "io/json_writer.hpp"
#include "io/pvd_writer.hpp"
#include "io/settings_json.hpp"
#include "io/vtu_format.hpp"

namespace contact3d {
namespace {

// One entry per Tresca (or frictionless) solve: the fixed-point history, or, when the scene needed
// a single solve (constant or no friction), that solve as step 1 with err = 0 (nothing depends on
// φ, so the first solve is the fixed point). Keeps history.csv, err_history, the progress lines,
// fixed_point_iterations and the steps of solution.pvd the same length.
std::vector<FixedPointStep> solve_history(const SolveResult& res) {
  if (!res.fixed_point.history.empty() || res.u_history.empty()) return res.fixed_point.history;
  double seconds = 0;
  for (const auto& [stage, sec] : res.seconds)
    if (stage == "dual_solve") seconds = sec;
  return {FixedPointStep{1, 0.0, res.qp_iterations, res.n_mult, seconds}};
}

bool has_friction(const SolveResult& res) { return res.lambda.size() == 3 * res.n_cells && res.n_cells > 0; }

double von_mises(const Mesh& mesh, const Matrix6d& D, const std::array<int, 4>& t, const Eigen::VectorXd& u) {
  TetCoords x{mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]};
  Eigen::Matrix<double, 12, 1> ue;
  for (int a = 0; a < 4; ++a)
    for (int c = 0; c < 3; ++c) ue[3 * a + c] = u[3 * t[a] + c];
  const Eigen::Matrix<double, 6, 1> s = D * (strain_matrix(x) * ue);
  return std::sqrt(0.5 * ((s[0] - s[1]) * (s[0] - s[1]) + (s[1] - s[2]) * (s[1] - s[2]) + (s[2] - s[0]) * (s[2] - s[0])) +
                   3 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
}

using vtu::data_array;

// Physical tag of each contact triangle (the contact group it was taken from) and the von Mises
// stress of the tetrahedron it bounds.
struct FaceCellData {
  std::vector<int> group;
  std::vector<double> von_mises;
};

std::array<int, 3> sorted3(std::array<int, 3> t) {
  std::sort(t.begin(), t.end());
  return t;
}

FaceCellData face_cell_data(const Scene& scene, const Mesh& mesh, const SolveResult& res, const std::vector<double>& vm) {
  std::set<int> contact_tags;
  for (const auto& name : scene.contact)
    if (const auto* g = mesh.find_group(name, 2)) contact_tags.insert(g->tag);
  std::map<std::array<int, 3>, int> tri_group;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    if (contact_tags.count(mesh.triangle_group[t])) tri_group.emplace(sorted3(mesh.triangles[t]), mesh.triangle_group[t]);
  std::map<std::array<int, 3>, int> wanted;
  for (std::size_t e = 0; e < res.face.triangles.size(); ++e) wanted.emplace(sorted3(res.face.triangles[e]), -1);
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const auto& t = mesh.tets[e];
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f{};
      for (int a = 0, j = 0; a < 4; ++a)
        if (a != skip) f[j++] = t[a];
      auto it = wanted.find(sorted3(f));
      if (it != wanted.end()) it->second = static_cast<int>(e);
    }
  }
  FaceCellData d;
  for (const auto& tri : res.face.triangles) {
    const auto key = sorted3(tri);
    const auto g = tri_group.find(key);
    d.group.push_back(g == tri_group.end() ? 0 : g->second);
    const int tet = wanted[key];
    d.von_mises.push_back(tet >= 0 ? vm[tet] : 0.0);
  }
  return d;
}

// Point data on Γc shared by body.vtu (zero off Γc) and contact.vtu: the nodal contact fields.
template <class Index>
void contact_point_data(std::ostream& out, const Mesh& mesh, const SolveResult& res, const ContactNodeFields& nf,
                        std::size_t n, Index global) {
  auto u = [&](std::size_t i, int c) { return res.u[3 * global(i) + c]; };
  // Normal and tangential parts are taken in the foundation plane's frame (u'_3 along its normal).
  auto local = [&](std::size_t i) -> Eigen::Vector3d { return res.frame.to_local(res.u.segment<3>(3 * global(i))); };
  data_array(out, "displacement", 3, n, u);
  data_array(out, "gap", 1, n, [&](std::size_t i, int) { return plane_gap(mesh, res, global(i)); });
  data_array(out, "wn", 1, n, [&](std::size_t i, int) { return -local(i).z(); });
  data_array(out, "slip", 3, n, [&](std::size_t i, int c) { return tangential_part(res.frame, local(i))[c]; });
  data_array(out, "slip_norm", 1, n, [&](std::size_t i, int) { return std::hypot(local(i).x(), local(i).y()); });
  data_array(out, "contact_pressure", 1, n, [&](std::size_t i, int) { return nf.pressure[global(i)]; });
  data_array(out, "tangential_traction", 3, n, [&](std::size_t i, int c) {
    return c == 0 ? nf.traction_t1[global(i)] : c == 1 ? nf.traction_t2[global(i)] : 0.0;
  });
  data_array(out, "friction_coefficient", 1, n, [&](std::size_t i, int) { return nf.friction[global(i)]; });
  data_array(out, "contact_status", 1, n, [&](std::size_t i, int) { return nf.status[global(i)]; }, "Int32");
}

// The whole body. Contact fields are those of contact.vtu at the nodes of Γc and zero elsewhere
// ("gap" is the distance z + u_3 to the plane at every node; "slip" is u_t on Γc only).
void write_body_vtu(const std::filesystem::path& file, const Mesh& mesh, const SolveResult& res,
                    const ContactNodeFields& nf, const std::vector<double>& vm) {
  write_file(file, [&](std::ostream& out) {
    const std::size_t n = mesh.nodes.size(), m = mesh.tets.size();
    std::vector<char> on_face(n, 0);
    for (const auto& tri : res.face.triangles)
      for (int v : tri) on_face[v] = 1;
    vtu::begin_piece(out, n, m);
    out << "      <PointData Vectors=\"displacement\">\n";
    auto u = [&](std::size_t i, int c) { return res.u[3 * i + c]; };
    data_array(out, "displacement", 3, n, u);
    data_array(out, "displacement_norm", 1, n, [&](std::size_t i, int) { return res.u.segment<3>(3 * i).norm(); });
    data_array(out, "gap", 1, n, [&](std::size_t i, int) { return plane_gap(mesh, res, static_cast<int>(i)); });
    data_array(out, "slip", 3, n, [&](std::size_t i, int c) {
      return on_face[i] ? tangential_part(res.frame, res.frame.to_local(res.u.segment<3>(3 * i)))[c] : 0.0;
    });
    data_array(out, "contact_pressure", 1, n, [&](std::size_t i, int) { return nf.pressure[i]; });
    data_array(out, "tangential_traction", 3, n, [&](std::size_t i, int c) {
      return c == 0 ? nf.traction_t1[i] : c == 1 ? nf.traction_t2[i] : 0.0;
    });
    data_array(out, "friction_coefficient", 1, n, [&](std::size_t i, int) { return nf.friction[i]; });
    data_array(out, "contact_status", 1, n, [&](std::size_t i, int) { return nf.status[i]; }, "Int32");
    data_array(out, "on_contact_face", 1, n, [&](std::size_t i, int) { return int(on_face[i]); }, "Int32");
    out << "      </PointData>\n      <CellData Scalars=\"von_mises\">\n";
    data_array(out, "von_mises", 1, m, [&](std::size_t e, int) { return vm[e]; });
    data_array(out, "physical_group", 1, m, [&](std::size_t e, int) { return mesh.tet_group[e]; }, "Int32");
    out << "      </CellData>\n";
    vtu::geometry(
        out, n, [&](std::size_t i, int c) { return mesh.nodes[i][c]; }, m, 4,
        [&](std::size_t e, int a) { return mesh.tets[e][a]; }, 10);
    vtu::end_piece(out);
  });
}

void write_contact_vtu(const std::filesystem::path& file, const Scene& scene, const Mesh& mesh, const SolveResult& res,
                       const ContactNodeFields& nf, const std::vector<double>& vm) {
  // Local numbering of the face's nodes (including those on Γu).
  std::vector<int> local(mesh.nodes.size(), -1), global;
  for (const auto& tri : res.face.triangles)
    for (int v : tri)
      if (local[v] < 0) { local[v] = static_cast<int>(global.size()); global.push_back(v); }
  const std::size_t n = global.size(), m = res.face.triangles.size();
  const FaceCellData cd = face_cell_data(scene, mesh, res, vm);
  write_file(file, [&](std::ostream& out) {
    vtu::begin_piece(out, n, m);
    out << "      <PointData Scalars=\"contact_pressure\" Vectors=\"displacement\">\n";
    contact_point_data(out, mesh, res, nf, n, [&](std::size_t i) { return global[i]; });
    out << "      </PointData>\n      <CellData Scalars=\"von_mises\">\n";
    data_array(out, "von_mises", 1, m, [&](std::size_t e, int) { return cd.von_mises[e]; });
    data_array(out, "physical_group", 1, m, [&](std::size_t e, int) { return cd.group[e]; }, "Int32");
    out << "      </CellData>\n";
    vtu::geometry(
        out, n, [&](std::size_t i, int c) { return mesh.nodes[global[i]][c]; }, m, 3,
        [&](std::size_t e, int a) { return local[res.face.triangles[e][a]]; }, 5);
    vtu::end_piece(out);
  });
}

void write_cells_vtu(const std::filesystem::path& file, const SolveResult& res) {
  std::vector<Eigen::Vector2d> pts;
  std::vector<std::size_t> offsets, owner;
  for (std::size_t i = 0; i < res.partition.cells.size(); ++i)
    for (const auto& piece : res.partition.cells[i].pieces) {
      for (const auto& v : piece.polygon) pts.push_back(v.xy);
      offsets.push_back(pts.size());
      owner.push_back(i);
    }
  const int r = res.n_cells;
  const bool fr = has_friction(res);
  write_file(file, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" << pts.size() << "\" NumberOfCells=\"" << owner.size()
        << "\">\n      <CellData Scalars=\"lambda_n\">\n";
    data_array(out, "cell", 1, owner.size(), [&](std::size_t k, int) { return owner[k]; }, "Int64");
    data_array(out, "lambda_n", 1, owner.size(), [&](std::size_t k, int) { return res.lambda[owner[k]]; });
    data_array(out, "lambda_t", 3, owner.size(), [&](std::size_t k, int c) {
      return fr && c < 2 ? res.lambda[(c + 1) * r + owner[k]] : 0.0;
    });
    data_array(out, "radius", 1, owner.size(), [&](std::size_t k, int) { return fr ? res.radius[owner[k]] : 0.0; });
    const std::vector<int> cs = cell_status(res);
    data_array(out, "contact_status", 1, owner.size(), [&](std::size_t k, int) { return cs[owner[k]]; }, "Int32");
    out << "      </CellData>\n      <Points>\n";
    data_array(out, "Points", 3, pts.size(), [&](std::size_t i, int c) {  // the cells lie in the foundation plane
      return res.frame.to_global_point(Eigen::Vector3d(pts[i].x(), pts[i].y(), 0.0))[c];
    });
    out << "      </Points>\n      <Cells>\n";
    data_array(out, "connectivity", 1, pts.size(), [](std::size_t k, int) { return k; }, "Int64");
    data_array(out, "offsets", 1, offsets.size(), [&](std::size_t e, int) { return offsets[e]; }, "Int64");
    data_array(out, "types", 1, owner.size(), [](std::size_t, int) { return 7; }, "UInt8");
    out << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  });
}

}  // namespace

double plane_gap(const Mesh& mesh, const SolveResult& res, int v) {
  return res.frame.to_local_point(mesh.nodes[v]).z() + res.frame.to_local(res.u.segment<3>(3 * v)).z();
}

Eigen::Vector3d tangential_part(const FoundationFrame& frame, const Eigen::Vector3d& local) {
  return frame.to_global(Eigen::Vector3d(local.x(), local.y(), 0.0));
}

std::vector<int> cell_status(const SolveResult& res) {
  const int r = res.n_cells;
  std::vector<int> status(r, 0);
  if (r == 0) return status;
  const bool fr = has_friction(res);
  const double pmax = res.lambda.head(r).maxCoeff();
  for (int i = 0; i < r; ++i) {
    if (res.lambda[i] <= 1e-6 * pmax) status[i] = 0;
    else if (fr && std::hypot(res.lambda[r + i], res.lambda[2 * r + i]) >= (1 - 1e-3) * res.radius[i]) status[i] = 2;
    else status[i] = 1;
  }
  return status;
}

ContactNodeFields contact_node_fields(const Mesh& mesh, const Scene& scene, const SolveResult& res) {
  const std::size_t nn = mesh.nodes.size();
  ContactNodeFields nf{Eigen::VectorXd::Zero(nn), Eigen::VectorXd::Zero(nn), Eigen::VectorXd::Zero(nn),
                       Eigen::VectorXd::Zero(nn), Eigen::VectorXd::Zero(nn), std::vector<int>(nn, 0)};
  if (res.n_cells == 0) return nf;
  const int r = res.n_cells;
  const bool fr = has_friction(res);
  const std::vector<int> cs = cell_status(res);
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(nn);
  std::vector<std::array<double, 3>> status_weight(nn, {0.0, 0.0, 0.0});
  const auto rows = cell_node_weights(res.face, res.partition);
  for (int i = 0; i < r; ++i)
    for (const auto& [node, w] : rows[i]) {
      weight[node] += w;
      status_weight[node][cs[i]] += w;
      nf.pressure[node] += w * res.lambda[i];
      if (fr) {
        nf.traction_t1[node] += w * res.lambda[r + i];
        nf.traction_t2[node] += w * res.lambda[2 * r + i];
        nf.radius[node] += w * res.radius[i];
      }
    }
  for (std::size_t v = 0; v < nn; ++v) {
    if (weight[v] <= 0) continue;
    nf.pressure[v] /= weight[v];
    nf.traction_t1[v] /= weight[v];
    nf.traction_t2[v] /= weight[v];
    nf.radius[v] /= weight[v];
    const double slip = res.frame.to_local(res.u.segment<3>(3 * v)).head<2>().norm();
    nf.friction[v] = scene.frictionless() ? 0.0 : scene.law(slip);
    // The status of the cells around the node, weighted by their share of its hat function (ties
    // go to the higher status): averaging the traction vectors instead would call a node between
    // slipping cells whose λ_t point in different directions "stick".
    const auto& sw = status_weight[v];
    nf.status[v] = sw[2] >= sw[1] && sw[2] >= sw[0] ? 2 : sw[1] >= sw[0] ? 1 : 0;
  }
  return nf;
}

void write_vector(JsonWriter& j, const char* key, const Eigen::Vector3d& v) {
  j.begin_array(key).element(v.x()).element(v.y()).element(v.z()).end_array();
}

// "forces": the resultants on the body (N, global x, y, z) and their balance.
void write_forces(JsonWriter& j, const ResultantForces& f) {
  j.begin_object("forces");
  write_vector(j, "applied", f.applied);
  write_vector(j, "contact", f.contact);
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

void write_summary_json(const std::filesystem::path& file, const Scene& scene, const Mesh& mesh, const SolveResult& res,
                        const RunInfo& info) {
  write_file(file, [&](std::ostream& out) {
    JsonWriter j(out);
    j.begin_object();
    j.value("status", res.status).value("converged", res.converged);
    j.value("mesh", info.mesh_description);
    j.value("n_nodes", static_cast<long long>(mesh.nodes.size())).value("n_tets", static_cast<long long>(mesh.tets.size()));
    j.value("n_primal", res.n_primal).value("n_dual", res.n_dual);
    j.value("n_contact_nodes", static_cast<long long>(res.face.nodes.size())).value("n_cells", res.n_cells);
    j.value("contact_h", res.face.h).value("cell_size", res.cell_size).value("cells_merged", res.partition.merged_slivers);
    j.value("cells_split", res.partition.split_cells).value("cells_merged_for_stability", res.partition.stability_merges);
    j.value("fixed_point_iterations", std::max(1, res.fixed_point.iterations()));
    j.value("n_mult", res.n_mult).value("qp_iterations", res.qp_iterations);
    j.value("schur_method", res.schur_method).value("qp_method", res.qp_method);
    j.value("friction_model", scene.frictionless() ? std::string("none") : name_of(scene.friction_model, kFrictionModelNames));
    j.value("qp_last_status", to_string(res.last_qp.status)).value("qp_last_projected_gradient", res.last_qp.projected_gradient);
    j.begin_array("err_history");
    for (const auto& s : solve_history(res)) j.element(s.err);
    j.end_array();
    if (!res.fixed_point.history.empty()) {  // how far the answer may be from the fixed point of (5.7)
      const FixedPointResult& fp = res.fixed_point;
      j.begin_object("fixed_point");
      j.value("contraction_factor", fp.contraction_factor);  // null before three steps
      j.value("contracted", fp.contraction_factor < 1);         // q < 1 observed over the last steps
      j.value("distance_bound", fp.distance_bound);          // q/(1 − q)·err; null when q >= 1 (no bound)
      j.value("qp_tolerance_tightenings", fp.qp_tolerance_tightenings);
      j.value("final_qp_rtol", fp.history.back().qp_rtol);
      j.value("hint", fp.hint);
      j.end_object();
    }
    j.value("wn_plus_L2", res.wn_plus_L2).value("wn_plus_inf", res.wn_plus_inf);
    j.value("stability_condition_estimate", res.stability_condition).value("factor_nonzeros", res.factor_nonzeros);
    j.begin_array("warnings");
    for (const auto& w : res.warnings) j.element(w);
    j.end_array();
    j.value("step_solve_fraction", res.step_solve_fraction);
    double force_n = 0, force_t1 = 0, force_t2 = 0;
    for (int i = 0; i < res.n_cells; ++i) {
      const double a = res.partition.cells[i].area;
      force_n += a * res.lambda[i];
      if (has_friction(res)) { force_t1 += a * res.lambda[res.n_cells + i]; force_t2 += a * res.lambda[2 * res.n_cells + i]; }
    }
    j.begin_object("contact_force").value("normal", force_n).value("t1", force_t1).value("t2", force_t2).end_object();
    if (has_friction(res)) {  // moment of the foundation's friction on the body about Γc's centroid, along n
      Eigen::Vector2d centre = Eigen::Vector2d::Zero();
      double area = 0;
      for (const auto& c : res.partition.cells) { centre += c.area * c.centroid; area += c.area; }
      if (area > 0) centre /= area;
      double torque = 0;
      for (int i = 0; i < res.n_cells; ++i) {
        const auto& c = res.partition.cells[i];
        const Eigen::Vector2d arm = c.centroid - centre;
        torque -= c.area * (arm.x() * res.lambda[2 * res.n_cells + i] - arm.y() * res.lambda[res.n_cells + i]);
      }
      j.value("friction_torque", torque);
    }
    j.value("max_penetration", res.wn_plus_inf);  // max nodal (w_n − d)⁺ on Γc, m
    {  // areas of the cells by status (in the plane; the cells' own areas)
      double area[3] = {0, 0, 0};
      const std::vector<int> status = cell_status(res);
      for (int i = 0; i < res.n_cells; ++i) area[status[i]] += res.partition.cells[i].area;
      const double no_friction = std::numeric_limits<double>::quiet_NaN();  // null: no stick/slip without friction
      j.begin_object("contact_area").value("in_contact", area[1] + area[2]);
      j.value("stick", has_friction(res) ? area[1] : no_friction).value("slip", has_friction(res) ? area[2] : no_friction);
      j.value("separated", area[0]).end_object();
    }
    write_forces(j, res.forces);
    j.begin_object("time_s");
    j.value("total", info.total_seconds).value("mesh", info.mesh_seconds);
    for (const auto& [stage, sec] : res.seconds) j.value(stage, sec);
    j.end_object();
    j.begin_object("kkt");
    j.value("equilibrium", res.kkt.equilibrium).value("normal_feasibility", res.kkt.normal_feasibility);
    j.value("normal_complementarity", res.kkt.normal_complementarity).value("disc_feasibility", res.kkt.disc_feasibility);
    j.value("slip_alignment", res.kkt.slip_alignment).value("projected_gradient", res.last_qp.projected_gradient);
    if (scene.coulomb()) j.value("coulomb_relation", res.coulomb_relation);  // max |c − F̄λ_n| / max c
    j.end_object();
    write_solver_settings(j, scene.solver);
    j.value("scene", scene.echo);
    j.end_object();
    out << "\n";
  });
}

void write_results(const std::filesystem::path& dir, const Scene& scene, const Mesh& mesh, const SolveResult& res,
                   const RunInfo& info) {
  const ContactNodeFields nf = contact_node_fields(mesh, scene, res);
  write_file(dir / "contact_nodes.csv", [&](std::ostream& out) {
    out << "node,x,y,z,u1,u2,u3,wn,wt_norm,F,pressure,status\n";
    for (int v : res.face.nodes) {
      const auto& x = mesh.nodes[v];
      const double u1 = res.u[3 * v], u2 = res.u[3 * v + 1], u3 = res.u[3 * v + 2];
      const Eigen::Vector3d local = res.frame.to_local(res.u.segment<3>(3 * v));  // wn, wt in the plane's frame
      out << mesh.node_tags[v] << ',' << x.x() << ',' << x.y() << ',' << x.z() << ',' << u1 << ',' << u2 << ',' << u3 << ','
          << -local.z() << ',' << local.head<2>().norm() << ',' << nf.friction[v] << ',' << nf.pressure[v] << ',' << nf.status[v] << '\n';
    }
  });
  write_file(dir / "contact_cells.csv", [&](std::ostream& out) {
    out << "cell,xmin,xmax,ymin,ymax,area,lambda_n,lambda_t1,lambda_t2,radius\n";
    const int r = res.n_cells;
    for (int i = 0; i < r; ++i) {
      const auto& c = res.partition.cells[i];
      const bool fr = has_friction(res);
      out << i << ',' << c.lo.x() << ',' << c.hi.x() << ',' << c.lo.y() << ',' << c.hi.y() << ',' << c.area << ','
          << res.lambda[i] << ',' << (fr ? res.lambda[r + i] : 0.0) << ',' << (fr ? res.lambda[2 * r + i] : 0.0) << ','
          << (fr ? res.radius[i] : 0.0) << '\n';
    }
  });
  write_file(dir / "history.csv", [&](std::ostream& out) {
    out << "k,err,qp_iterations,n_mult,seconds\n";
    for (const auto& s : solve_history(res))
      out << s.k << ',' << s.err << ',' << s.qp_iterations << ',' << s.n_mult << ',' << s.seconds << '\n';
  });
  const Matrix6d D = hooke_matrix(scene.material);
  std::vector<double> vm(mesh.tets.size());
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) vm[e] = von_mises(mesh, D, mesh.tets[e], res.u);
  write_body_vtu(dir / "body.vtu", mesh, res, nf, vm);
  if (res.n_cells > 0) {
    write_contact_vtu(dir / "contact.vtu", scene, mesh, res, nf, vm);
    write_cells_vtu(dir / "contact_cells.vtu", res);
    write_solution_steps(dir, scene, mesh, res);
  }
  write_summary_json(dir / "summary.json", scene, mesh, res, info);
}

}  // namespace contact3d
