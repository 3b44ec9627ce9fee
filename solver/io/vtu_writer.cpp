#include "io/vtu_writer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

#include "io/atomic_file.hpp"

namespace contact3d {
namespace {

std::array<int, 3> sorted3(std::array<int, 3> t) {
  std::sort(t.begin(), t.end());
  return t;
}

// The contact traction on the body at node v, in the user's axes: the pressure along the plane's
// normal (into the body) and the friction traction −λ_t.
Eigen::Vector3d traction_on_body(const FoundationFrame& frame, const ContactNodeFields& nf, int v, bool with_normal) {
  const Eigen::Vector3d local(-nf.traction_t1[v], -nf.traction_t2[v], with_normal ? nf.pressure[v] : 0.0);
  return frame.to_global(local);
}

// Point data shared by body.vtu (every node; contact fields zero off Γc) and contact.vtu.
// `node(i)` is the mesh node of point i.
template <class NodeOf>
void contact_point_data(vtu::PieceWriter& piece, const VtuContext& ctx, const StateView& s, const ContactNodeFields& nf,
                        const std::vector<char>& on_face, std::size_t n, NodeOf node) {
  const FoundationFrame& frame = ctx.res.frame;
  auto local = [&](std::size_t i) -> Eigen::Vector3d { return frame.to_local(s.u.segment<3>(3 * node(i))); };
  piece.data_array("gap", 1, n, [&](std::size_t i, int) { return plane_gap(ctx.mesh, frame, s.u, node(i)); });
  piece.data_array("slip", 3, n,
                   [&](std::size_t i, int c) { return on_face[node(i)] ? tangential_part(frame, local(i))[c] : 0.0; });
  piece.data_array("contact_pressure", 1, n, [&](std::size_t i, int) { return nf.pressure[node(i)]; });
  piece.data_array("tangential_traction", 3, n,
                   [&](std::size_t i, int c) { return traction_on_body(frame, nf, node(i), false)[c]; });
  piece.data_array("traction_on_body", 3, n,
                   [&](std::size_t i, int c) { return traction_on_body(frame, nf, node(i), true)[c]; });
  piece.data_array("friction_coefficient", 1, n, [&](std::size_t i, int) { return nf.friction[node(i)]; });
  piece.data_array(
      "contact_status", 1, n, [&](std::size_t i, int) { return nf.status[node(i)]; }, vtu::Type::Int32);
}

// Cell data: the stress of tetrahedron tet(e) for cell e.
template <class TetOf>
void stress_cell_data(vtu::PieceWriter& piece, const TetStress& stress, std::size_t m, TetOf tet) {
  piece.data_array("stress", 9, m, [&](std::size_t e, int c) {
    const int t = tet(e);
    return t < 0 ? 0.0 : stress.tensor(static_cast<std::size_t>(t))(c / 3, c % 3);
  });
  piece.data_array("von_mises", 1, m, [&](std::size_t e, int) {
    const int t = tet(e);
    return t < 0 ? 0.0 : stress.von_mises[static_cast<std::size_t>(t)];
  });
}

// One state's fields, shared by its body and contact files.
struct StateFields {
  ContactNodeFields contact;
  TetStress stress;
};

void write_body_vtu(const std::filesystem::path& file, const VtuContext& ctx, const StateView& s,
                    const StateFields& fields) {
  const Mesh& mesh = ctx.mesh;
  const ContactNodeFields& nf = fields.contact;
  const TetStress& stress = fields.stress;
  const std::vector<char>& on_face = ctx.on_face;
  write_file(file, [&](std::ostream& out) {
    const std::size_t n = mesh.nodes.size(), m = mesh.tets.size();
    vtu::write_piece(out, ctx.encoding, n, m, [&](vtu::PieceWriter& piece) {
      piece.xml("      <PointData Vectors=\"displacement\">\n");
      piece.data_array("displacement", 3, n, [&](std::size_t i, int c) { return s.u[3 * i + c]; });
      piece.data_array("displacement_norm", 1, n, [&](std::size_t i, int) { return s.u.segment<3>(3 * i).norm(); });
      contact_point_data(piece, ctx, s, nf, on_face, n, [](std::size_t i) { return static_cast<int>(i); });
      piece.data_array(
          "on_contact_face", 1, n, [&](std::size_t i, int) { return int(on_face[i]); }, vtu::Type::Int32);
      piece.xml("      </PointData>\n      <CellData Scalars=\"von_mises\" Tensors=\"stress\">\n");
      stress_cell_data(piece, stress, m, [](std::size_t e) { return static_cast<int>(e); });
      piece.data_array(
          "physical_group", 1, m, [&](std::size_t e, int) { return mesh.tet_group[e]; }, vtu::Type::Int32);
      piece.xml("      </CellData>\n");
      piece.geometry(
          n, [&](std::size_t i, int c) { return mesh.nodes[i][c]; }, m, 4,
          [&](std::size_t e, int a) { return mesh.tets[e][a]; }, 10);
    });
  });
}

void write_contact_vtu(const std::filesystem::path& file, const VtuContext& ctx, const StateView& s,
                       const StateFields& fields) {
  const Mesh& mesh = ctx.mesh;
  const ContactFace& face = ctx.res.face;
  std::vector<int> local(mesh.nodes.size(), -1), global;  // the face's own numbering of its nodes
  for (const auto& tri : face.triangles)
    for (int v : tri)
      if (local[v] < 0) {
        local[v] = static_cast<int>(global.size());
        global.push_back(v);
      }
  const std::size_t n = global.size(), m = face.triangles.size();
  const ContactNodeFields& nf = fields.contact;
  const TetStress& stress = fields.stress;
  const std::vector<char>& on_face = ctx.on_face;
  write_file(file, [&](std::ostream& out) {
    vtu::write_piece(out, ctx.encoding, n, m, [&](vtu::PieceWriter& piece) {
      piece.xml("      <PointData Scalars=\"contact_pressure\" Vectors=\"displacement\">\n");
      auto node = [&](std::size_t i) { return global[i]; };
      auto local_u = [&](std::size_t i) -> Eigen::Vector3d {
        return ctx.res.frame.to_local(s.u.segment<3>(3 * node(i)));
      };
      piece.data_array("displacement", 3, n, [&](std::size_t i, int c) { return s.u[3 * node(i) + c]; });
      piece.data_array("wn", 1, n, [&](std::size_t i, int) { return -local_u(i).z(); });
      piece.data_array("slip_norm", 1, n, [&](std::size_t i, int) { return local_u(i).head<2>().norm(); });
      contact_point_data(piece, ctx, s, nf, on_face, n, node);
      piece.xml("      </PointData>\n      <CellData Scalars=\"von_mises\" Tensors=\"stress\">\n");
      stress_cell_data(piece, stress, m, [&](std::size_t e) { return ctx.face_tet[e]; });
      piece.data_array(
          "physical_group", 1, m, [&](std::size_t e, int) { return ctx.face_group[e]; }, vtu::Type::Int32);
      piece.xml("      </CellData>\n");
      piece.geometry(
          n, [&](std::size_t i, int c) { return mesh.nodes[global[i]][c]; }, m, 3,
          [&](std::size_t e, int a) { return local[face.triangles[e][a]]; }, 5);
    });
  });
}

}  // namespace

VtuContext::VtuContext(const Scene& scene_, const Mesh& mesh_, const SolveResult& res_, const TetMaterials& materials_)
    : scene(scene_),
      mesh(mesh_),
      res(res_),
      materials(materials_),
      on_face(mesh_.nodes.size(), 0),
      encoding(binary_vtu(scene_.output.vtu, mesh_.nodes.size()) ? vtu::Encoding::Binary : vtu::Encoding::Ascii) {
  const ContactFace& face = res.face;
  for (const auto& tri : face.triangles)
    for (int v : tri) on_face[v] = 1;
  std::set<int> contact_tags;
  for (const auto& name : scene.contact)
    if (const auto* g = mesh.find_group(name, 2)) contact_tags.insert(g->tag);
  std::map<std::array<int, 3>, int> tri_group;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    if (contact_tags.count(mesh.triangle_group[t]))
      tri_group.emplace(sorted3(mesh.triangles[t]), mesh.triangle_group[t]);
  std::map<std::array<int, 3>, int> owner;
  for (const auto& tri : face.triangles) owner.emplace(sorted3(tri), -1);
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const auto& t = mesh.tets[e];
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f{};
      for (int a = 0, j = 0; a < 4; ++a)
        if (a != skip) f[j++] = t[a];
      auto it = owner.find(sorted3(f));
      if (it != owner.end()) it->second = static_cast<int>(e);
    }
  }
  for (const auto& tri : face.triangles) {
    const auto key = sorted3(tri);
    const auto g = tri_group.find(key);
    face_group.push_back(g == tri_group.end() ? 0 : g->second);
    face_tet.push_back(owner[key]);
  }
}

void write_state_vtus(const std::filesystem::path& body_file, const std::filesystem::path& contact_file,
                      const VtuContext& ctx, const StateView& state) {
  const StateFields fields{contact_node_fields(ctx.mesh, ctx.scene, ctx.res, state),
                           tet_stresses(ctx.mesh, ctx.materials, state.u)};
  write_body_vtu(body_file, ctx, state, fields);
  if (!ctx.res.face.triangles.empty()) write_contact_vtu(contact_file, ctx, state, fields);
}

}  // namespace contact3d
