#include "mesh/mesh_checks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <tuple>

#include <Eigen/Dense>

#include "base/errors.hpp"
#include "base/format.hpp"

namespace contact3d {
namespace {

template <std::size_t N>
std::array<int, N> sorted(std::array<int, N> a) {
  std::sort(a.begin(), a.end());
  return a;
}

std::string tag_list(const std::vector<std::size_t>& tags) {
  std::string out;
  for (std::size_t k = 0; k < tags.size() && k < 4; ++k) out += (k ? ", " : "") + std::to_string(tags[k]);
  return out + (tags.size() > 4 ? ", ..." : "");
}

}  // namespace

void check_coordinates_in_range(const Mesh& mesh) {
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
    for (int c = 0; c < 3; ++c)
      if (!(std::abs(mesh.nodes[v][c]) <= kMaxCoordinate))
        throw InputError("node " + std::to_string(mesh.node_tags[v]) + " has coordinate " + "xyz"[c] + " = " +
                         number(mesh.nodes[v][c]) +
                         ", beyond ±1e15: the mesh's units are wrong or the file is corrupt");
}

namespace {

// Each group by the name a scene gives it: its own, or an unnamed one's number (gmsh's physical
// groups without $PhysicalNames, as FreeFEM's savegmsh writes them), so "4" may not be both.
void check_group_names(const Mesh& mesh) {
  std::set<std::pair<int, std::string>> seen;
  for (const auto& g : mesh.groups) {
    const std::string scene_name = g.name.empty() ? std::to_string(g.tag) : g.name;
    if (!seen.insert({g.dim, scene_name}).second)
      throw InputError("the mesh has two physical groups of dimension " + std::to_string(g.dim) + " named '" +
                       scene_name + "' (an unnamed group goes by its number); a scene names groups by name, " +
                       "so each name must be used once per dimension");
  }
}

void check_duplicate_tets(const Mesh& mesh) {
  std::vector<std::pair<std::array<int, 4>, std::size_t>> keyed(mesh.tets.size());
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) keyed[e] = {sorted(mesh.tets[e]), e};
  std::sort(keyed.begin(), keyed.end());
  for (std::size_t k = 1; k < keyed.size(); ++k)
    if (keyed[k].first == keyed[k - 1].first)
      throw InputError("tetrahedra " + std::to_string(mesh.tet_tags[keyed[k - 1].second]) + " and " +
                       std::to_string(mesh.tet_tags[keyed[k].second]) +
                       " have the same four nodes: the body would be assembled twice there (a duplicated element)");
}

// Each face of each tetrahedron, with the side of the face its tetrahedron lies on: in a mesh of
// positively oriented tetrahedra that fill the body once, a face belongs to one tetrahedron (the
// boundary) or to two on opposite sides of it. A face of three, or of two on one side, means
// elements overlap (an element added by hand, two meshes written into one file).
struct TetFace {
  std::array<int, 3> nodes;  // sorted
  std::uint32_t tet;
  bool side;  // which side of the face the tetrahedron is on (the parity of its outward orientation)
  bool operator<(const TetFace& o) const { return std::tie(nodes, tet) < std::tie(o.nodes, o.tet); }
};
std::vector<TetFace> tet_faces(const Mesh& mesh) {
  std::vector<TetFace> faces;
  faces.reserve(4 * mesh.tets.size());
  for (std::size_t e = 0; e < mesh.tets.size(); ++e)
    for (int skip = 0; skip < 4; ++skip) {
      // The face opposite local vertex `skip`, its vertices in local order: outward when skip is even
      // (the boundary of [v0 v1 v2 v3] is the sum of (-1)^k times the face without v_k); only the
      // parities of two tetrahedra on one face are compared, so the convention's sign does not matter.
      std::array<int, 3> f{};
      for (int a = 0, j = 0; a < 4; ++a)
        if (a != skip) f[j++] = mesh.tets[e][a];
      bool odd = skip % 2 == 1;
      for (int i = 0; i < 3; ++i)  // sorting by swaps; each swap flips the orientation
        for (int j = 0; j + 1 < 3 - i; ++j)
          if (f[j] > f[j + 1]) {
            std::swap(f[j], f[j + 1]);
            odd = !odd;
          }
      faces.push_back({f, static_cast<std::uint32_t>(e), odd});
    }
  std::sort(faces.begin(), faces.end());
  return faces;
}

void check_tets_do_not_overlap(const Mesh& mesh, const std::vector<TetFace>& faces) {
  const auto tag = [&](const TetFace& f) { return std::to_string(mesh.tet_tags[f.tet]); };
  const auto face_nodes = [&](const TetFace& f) {
    return std::to_string(mesh.node_tags[f.nodes[0]]) + ", " + std::to_string(mesh.node_tags[f.nodes[1]]) + ", " +
           std::to_string(mesh.node_tags[f.nodes[2]]);
  };
  for (std::size_t k = 1; k < faces.size(); ++k) {
    if (faces[k].nodes != faces[k - 1].nodes) continue;
    if (k >= 2 && faces[k].nodes == faces[k - 2].nodes)
      throw InputError("tetrahedra " + tag(faces[k - 2]) + ", " + tag(faces[k - 1]) + " and " + tag(faces[k]) +
                       " share the face of nodes " + face_nodes(faces[k]) +
                       ": a face belongs to at most two tetrahedra, so elements overlap there (an element added "
                       "to the mesh, or two meshes written into one file)");
    if (faces[k].side == faces[k - 1].side)
      throw InputError("tetrahedra " + tag(faces[k - 1]) + " and " + tag(faces[k]) + " share the face of nodes " +
                       face_nodes(faces[k]) +
                       " and lie on the same side of it: they overlap (an element added to the mesh, or two "
                       "meshes written into one file)");
  }
}

// Points (each with the tetrahedron it belongs to) in a balanced k-d tree, for finding those inside
// tetrahedra: the overlap check's centres, the touching faces' points outside the body. (A uniform
// grid was tried first: on a mesh graded from 0.8 mm to centimetres its cells either held thousands of
// points or outnumbered the tetrahedra.)
class PointTree {
 public:
  struct Point {
    Eigen::Vector3d at;
    std::uint32_t tet;    // the tetrahedron it belongs to (not looked for in it)
    std::uint32_t label;  // the caller's number for it
  };

  explicit PointTree(std::vector<Point> points) : points_(std::move(points)), axis_(points_.size()) {
    build(0, points_.size());
  }

  // Calls visit(point) for each point in the box [lo, hi].
  template <class Visit>
  void for_points_in(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, Visit&& visit) const {
    query(0, points_.size(), lo, hi, visit);
  }

 private:
  static constexpr std::size_t kLeaf = 8;

  // Node [b, e): its splitting point in the middle, the points below it along axis_[middle] before,
  // those above after.
  void build(std::size_t b, std::size_t e) {
    if (e - b <= kLeaf) return;
    Eigen::Vector3d lo = points_[b].at, hi = lo;
    for (std::size_t k = b; k < e; ++k) {
      lo = lo.cwiseMin(points_[k].at);
      hi = hi.cwiseMax(points_[k].at);
    }
    Eigen::Index axis = 0;
    (hi - lo).maxCoeff(&axis);
    const std::size_t mid = b + (e - b) / 2;
    const auto first = points_.begin();
    std::nth_element(first + static_cast<std::ptrdiff_t>(b), first + static_cast<std::ptrdiff_t>(mid),
                     first + static_cast<std::ptrdiff_t>(e),
                     [axis](const Point& x, const Point& y) { return x.at[axis] < y.at[axis]; });
    axis_[mid] = static_cast<std::uint8_t>(axis);
    build(b, mid);
    build(mid + 1, e);
  }

  static bool in_box(const Eigen::Vector3d& c, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    return (c.array() >= lo.array()).all() && (c.array() <= hi.array()).all();
  }

  template <class Visit>
  void query(std::size_t b, std::size_t e, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, Visit& visit) const {
    if (e - b <= kLeaf) {
      for (std::size_t k = b; k < e; ++k)
        if (in_box(points_[k].at, lo, hi)) visit(points_[k]);
      return;
    }
    const std::size_t mid = b + (e - b) / 2;
    const int axis = axis_[mid];
    const double split = points_[mid].at[axis];
    if (lo[axis] <= split) query(b, mid, lo, hi, visit);
    if (in_box(points_[mid].at, lo, hi)) visit(points_[mid]);
    if (hi[axis] >= split) query(mid + 1, e, lo, hi, visit);
  }

  std::vector<Point> points_;
  std::vector<std::uint8_t> axis_;  // the splitting axis of the node whose middle is this position
};

// Calls found(point, tet) for each point of the tree inside a tetrahedron other than its own, all four
// barycentric coordinates above `margin`; found returns false to stop.
template <class Found>
void for_points_inside_other_tets(const Mesh& mesh, const PointTree& tree, double margin, Found&& found) {
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const auto& t = mesh.tets[e];
    const Eigen::Vector3d& p0 = mesh.nodes[t[0]];
    Eigen::Vector3d lo = p0, hi = p0;
    for (const int v : t) {
      lo = lo.cwiseMin(mesh.nodes[v]);
      hi = hi.cwiseMax(mesh.nodes[v]);
    }
    Eigen::Matrix3d to_barycentric;
    bool have_map = false, go_on = true;
    tree.for_points_in(lo, hi, [&](const PointTree::Point& point) {
      if (!go_on || point.tet == e) return;
      if (!have_map) {
        Eigen::Matrix3d edges;
        for (int j = 0; j < 3; ++j) edges.col(j) = mesh.nodes[t[j + 1]] - p0;
        to_barycentric = edges.inverse();  // positively oriented (checked before): invertible
        have_map = true;
      }
      const Eigen::Vector3d l = to_barycentric * (point.at - p0);
      if (l.minCoeff() > margin && 1.0 - l.sum() > margin) go_on = found(point, e);
    });
    if (!go_on) return;
  }
}

// Whether faces[k] (the sorted faces of tet_faces) lies on the boundary: a face of no other tetrahedron.
bool face_on_the_boundary(const std::vector<TetFace>& faces, std::size_t k) {
  return !(k > 0 && faces[k - 1].nodes == faces[k].nodes) &&
         !(k + 1 < faces.size() && faces[k + 1].nodes == faces[k].nodes);
}

// Whether each tetrahedron lies in a block of its part other than the part's largest: an element laid
// over nodes of the body, or volumes merged at a few nodes (blocks_joined_at_nodes).
// `block_of_tet`, `blocks`: face_connected_blocks.
std::vector<char> in_minor_blocks(const Mesh& mesh, const std::vector<int>& block_of_tet, int blocks) {
  const BodyParts parts = body_parts(mesh);
  std::vector<std::size_t> size(static_cast<std::size_t>(blocks), 0);
  for (const int b : block_of_tet) ++size[static_cast<std::size_t>(b)];
  const auto part_of = [&](std::size_t e) {
    return static_cast<std::size_t>(parts.of_node[static_cast<std::size_t>(mesh.tets[e][0])]);
  };
  std::vector<int> largest(static_cast<std::size_t>(parts.count()), -1);
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    int& top = largest[part_of(e)];
    const int b = block_of_tet[e];
    if (top < 0 || size[static_cast<std::size_t>(b)] > size[static_cast<std::size_t>(top)]) top = b;
  }
  std::vector<char> minor(mesh.tets.size(), 0);
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) minor[e] = block_of_tet[e] != largest[part_of(e)];
  return minor;
}

// Blocks of a mesh (tetrahedra joined through faces) that overlap: two gmsh volumes meshed over the same
// place without BooleanFragments, two meshes written into one file, an element over new nodes or laid
// over nodes of the body through its inside — a point of a tetrahedron of one lies inside a tetrahedron of
// another. In a mesh that fills the body once, each tetrahedron's centre is inside it alone, a quarter of
// its heights away from its faces, so blocks that touch along a face (curved or not) are not taken for an
// overlap; a margin of 1e-3 of the barycentric coordinates keeps rounding out too. The points looked for:
// the centres of tetrahedra on the boundary (two blocks over each other have their outer layers inside
// each other), and for the tetrahedra of a block joined to its part at nodes only also the points half way
// from the centre to each corner (one element over three nodes of a structured mesh can have its centre
// on the faces the body's tetrahedra share). Only where the mesh has several blocks: the common mesh of
// one block pays face_connected_blocks, not the search. Overlaps through a face are
// check_tets_do_not_overlap's.
void check_no_tet_holds_another_centre(const Mesh& mesh, const std::vector<TetFace>& faces, const MeshRoles& roles) {
  int blocks = 0;
  const std::vector<int> block_of_tet = face_connected_blocks(mesh, blocks);
  if (blocks < 2) return;
  const std::vector<char> minor = in_minor_blocks(mesh, block_of_tet, blocks);
  std::vector<char> on(mesh.tets.size(), 0);
  for (std::size_t k = 0; k < faces.size(); ++k)
    if (face_on_the_boundary(faces, k)) on[faces[k].tet] = 1;
  constexpr std::uint32_t kCentre = 0, kInside = 1;  // a point's label: the centre, or half way to a corner
  std::vector<PointTree::Point> points;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    if (!on[e] && !minor[e]) continue;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const int v : mesh.tets[e]) c += mesh.nodes[v];
    c /= 4.0;
    const auto tet = static_cast<std::uint32_t>(e);
    points.push_back({c, tet, kCentre});
    if (minor[e])
      for (const int v : mesh.tets[e]) points.push_back({0.5 * (c + mesh.nodes[v]), tet, kInside});
  }
  for_points_inside_other_tets(
      mesh, PointTree(std::move(points)), 1e-3, [&](const PointTree::Point& point, std::size_t holder) -> bool {
        const Eigen::Vector3d at = roles.user_point ? roles.user_point(point.at) : point.at;
        throw InputError(std::string(point.label == kCentre ? "the centre" : "a point") + " of tetrahedron " +
                         std::to_string(mesh.tet_tags[point.tet]) + ", (" + number(at.x()) + ", " + number(at.y()) +
                         ", " + number(at.z()) + "), lies inside tetrahedron " + std::to_string(mesh.tet_tags[holder]) +
                         ": elements overlap (an element added to the mesh or laid over nodes of the body, two meshes "
                         "written into one file, or two volumes meshed over the same place)");
      });
}

int group_tag(const Mesh& mesh, const std::string& name) {
  const PhysicalGroup* g = mesh.find_group(name, 2);
  return g ? g->tag : -1;  // a missing group is reported where the scene's groups are resolved
}

// A triangle twice in one group, or in two of the load groups.
void check_duplicate_triangles(const Mesh& mesh, const MeshRoles& roles) {
  std::map<std::pair<std::array<int, 3>, int>, std::size_t> in_group;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto [it, fresh] = in_group.emplace(std::make_pair(sorted(mesh.triangles[t]), mesh.triangle_group[t]), t);
    if (!fresh && mesh.triangle_group[t] != 0) {
      std::string name = std::to_string(mesh.triangle_group[t]);
      for (const auto& g : mesh.groups)
        if (g.dim == 2 && g.tag == mesh.triangle_group[t]) name = g.name;
      throw InputError("triangles " + std::to_string(mesh.triangle_tags[it->second]) + " and " +
                       std::to_string(mesh.triangle_tags[t]) + " of group '" + name +
                       "' have the same three nodes: a load or constraint on that group would count them twice");
    }
  }
  std::map<std::array<int, 3>, std::string> loaded_by;
  for (const auto& name : roles.loaded) {
    const int tag = group_tag(mesh, name);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      if (mesh.triangle_group[t] != tag) continue;
      const auto [it, fresh] = loaded_by.emplace(sorted(mesh.triangles[t]), name);
      if (!fresh && it->second != name)
        throw InputError("triangle " + std::to_string(mesh.triangle_tags[t]) + " is in the load groups '" + it->second +
                         "' and '" + name + "': its load would be applied twice");
    }
  }
}

// Γc must be a graph over the foundation plane: its outward normal points down (n_z < 0) on every
// triangle. A triangle facing up or sideways means the face folds over itself, or rises
// vertically, above the plane, where the projection onto the cells would count it twice. A group
// none of whose triangles faces down is the other side of the body, or a plane normal pointing
// away from the body (contact.plane_normal = [0, 0, -1] under a body resting on z = 0 was reported
// as one triangle that "folds over itself or rises vertically").
void check_contact_is_graph(const Mesh& mesh, const std::map<std::array<int, 3>, std::vector<std::size_t>>& wanted,
                            std::map<std::array<int, 3>, int>& count, std::map<std::array<int, 3>, int>& opposite,
                            const std::map<int, std::string>& group_names) {
  bool any_facing_down = false;
  std::size_t first_away = 0;
  Eigen::Vector3d away_normal = Eigen::Vector3d::Zero();
  for (const auto& [face, tris] : wanted) {
    if (count[face] != 1) continue;  // orphans and interior faces are reported below
    const Eigen::Vector3d a = mesh.nodes[face[0]], b = mesh.nodes[face[1]], c = mesh.nodes[face[2]];
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.dot(mesh.nodes[opposite[face]] - a) > 0) n = -n;  // outward: away from the tet
    if (n.z() < -1e-6 * n.norm()) {
      any_facing_down = true;
    } else if (away_normal.isZero()) {
      first_away = tris.front();
      away_normal = n.normalized();
    }
  }
  if (away_normal.isZero()) return;
  const std::string group = group_names.at(mesh.triangle_group[first_away]);
  auto component = [](double c) { return number(std::abs(c) < 1e-9 ? 0.0 : c); };  // no -0 or 1e-16 of rounding
  const std::string normal =
      "(" + component(away_normal.x()) + ", " + component(away_normal.y()) + ", " + component(away_normal.z()) + ")";
  if (!any_facing_down)
    throw InputError("contact group '" + group + "': none of its triangles faces the foundation (triangle " +
                     std::to_string(mesh.triangle_tags[first_away]) + ": outward normal " + normal +
                     " in the plane's frame, whose +z points from the plane to the body; Γc must be a graph over "
                     "the plane z = 0, seen from below): either the group is a face of the body that looks away "
                     "from the foundation, or contact.plane_normal points away from the body (it must point from "
                     "the foundation plane towards the body)");
  throw InputError("contact group '" + group + "': triangle " + std::to_string(mesh.triangle_tags[first_away]) +
                   " faces away from the foundation (outward normal " + normal +
                   "): Γc must be a graph over the plane z = 0, seen from below — it folds over itself or "
                   "rises vertically there; put only the part of the surface that faces the foundation in the "
                   "contact group");
}

// How many tetrahedra have each of the wanted faces (sorted node triples) as a face, and the fourth
// node of the last such tetrahedron (it fixes the outward side).
struct FaceUse {
  std::map<std::array<int, 3>, int> count, opposite;
  int tets_on(const std::array<int, 3>& face) const {
    const auto it = count.find(face);
    return it == count.end() ? 0 : it->second;
  }
};
template <class Faces>
FaceUse face_use(const Mesh& mesh, const Faces& wanted) {
  FaceUse use;
  std::vector<char> on_face(mesh.nodes.size(), 0);
  for (const auto& [face, tris] : wanted)
    for (int v : face) on_face[v] = 1;
  for (const auto& tet : mesh.tets)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f{};
      for (int a = 0, j = 0; a < 4; ++a)
        if (a != skip) f[j++] = tet[a];
      if (!on_face[f[0]] || !on_face[f[1]] || !on_face[f[2]]) continue;
      f = sorted(f);
      if (wanted.count(f)) {
        ++use.count[f];
        use.opposite[f] = tet[skip];
      }
    }
  return use;
}

using WantedFaces = std::map<std::array<int, 3>, std::vector<std::size_t>>;  // sorted face -> its triangles

// The triangles (indices) of `wanted` that are a face of no tetrahedron, and those that two share.
struct MisplacedTriangles {
  std::vector<std::size_t> orphans, interior;
};
MisplacedTriangles misplaced_triangles(const WantedFaces& wanted, const FaceUse& use) {
  MisplacedTriangles found;
  for (const auto& [face, tris] : wanted) {
    const int n = use.tets_on(face);
    for (std::size_t t : tris) {
      if (n == 0) found.orphans.push_back(t);
      if (n > 1) found.interior.push_back(t);
    }
  }
  return found;
}

std::vector<std::size_t> file_tags(const Mesh& mesh, const std::vector<std::size_t>& triangles) {
  std::vector<std::size_t> tags;
  for (std::size_t t : triangles) tags.push_back(mesh.triangle_tags[t]);
  return tags;
}

// Every contact triangle must be the face of exactly one tetrahedron.
void check_contact_faces(const Mesh& mesh, const MeshRoles& roles) {
  WantedFaces wanted;
  std::map<int, std::string> group_names;
  for (const auto& name : roles.contact) {
    const int tag = group_tag(mesh, name);
    group_names[tag] = name;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
      if (mesh.triangle_group[t] == tag) wanted[sorted(mesh.triangles[t])].push_back(t);
  }
  if (wanted.empty()) return;
  FaceUse use = face_use(mesh, wanted);
  check_contact_is_graph(mesh, wanted, use.count, use.opposite, group_names);
  const MisplacedTriangles found = misplaced_triangles(wanted, use);
  if (!found.orphans.empty())
    throw InputError(
        std::to_string(found.orphans.size()) + " contact triangle(s) are not a face of any tetrahedron (tags " +
        tag_list(file_tags(mesh, found.orphans)) +
        "): the contact group does not lie on the body's surface, or the volume under it is not in the mesh (gmsh "
        "saves only the elements of physical groups: is every volume in a Physical Volume?)");
  if (!found.interior.empty())
    throw InputError(std::to_string(found.interior.size()) +
                     " contact triangle(s) are interior faces, shared by two "
                     "tetrahedra (tags " +
                     tag_list(file_tags(mesh, found.interior)) + "): Γc must be part of the body's boundary");
}

double area_of(const Mesh& mesh, const std::vector<std::size_t>& triangles) {
  double area = 0;
  for (std::size_t t : triangles) area += triangle_area(mesh, mesh.triangles[t]);
  return area;
}

// Every triangle of a traction or pressure group must be the face of exactly one tetrahedron: a
// surface load on a face inside the body (typically the cut face of a gmsh BooleanFragments that a
// "Surface In BoundingBox" selection picked up with the outer surface) would add its load there,
// silently. One pass over the tetrahedra for every load group (a triangle in two of them is refused
// before, check_duplicate_triangles).
void check_load_faces(const Mesh& mesh, const MeshRoles& roles) {
  std::vector<std::pair<std::string, WantedFaces>> groups;
  WantedFaces all;
  for (const auto& name : roles.loaded) {
    const int tag = group_tag(mesh, name);
    WantedFaces wanted;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
      if (mesh.triangle_group[t] == tag) wanted[sorted(mesh.triangles[t])].push_back(t);
    for (const auto& [face, tris] : wanted) all[face].insert(all[face].end(), tris.begin(), tris.end());
    groups.emplace_back(name, std::move(wanted));
  }
  if (all.empty()) return;
  const FaceUse use = face_use(mesh, all);
  for (const auto& [name, wanted] : groups) {
    const MisplacedTriangles found = misplaced_triangles(wanted, use);
    if (!found.orphans.empty())
      throw InputError("load group '" + name + "': " + std::to_string(found.orphans.size()) +
                       " triangle(s) are not a face of any tetrahedron (tags " +
                       tag_list(file_tags(mesh, found.orphans)) +
                       "): a traction or pressure acts on the body's boundary (gmsh saves only the elements of "
                       "physical groups: is every volume in a Physical Volume?)");
    if (found.interior.empty()) continue;
    std::vector<std::size_t> group;
    for (const auto& [face, tris] : wanted) group.insert(group.end(), tris.begin(), tris.end());
    throw InputError("load group '" + name + "': " + std::to_string(found.interior.size()) + " of its " +
                     std::to_string(group.size()) + " triangles are interior faces, shared by two tetrahedra (tags " +
                     tag_list(file_tags(mesh, found.interior)) + "; " + number(area_of(mesh, found.interior)) +
                     " of the group's area " + number(area_of(mesh, group)) +
                     "): a traction or pressure acts on the body's boundary, so the load there would act "
                     "inside the body. Remove those faces from the group (a surface cut by gmsh's "
                     "BooleanFragments stays in the mesh, and a 'Surface In BoundingBox' selection picks it up)");
  }
}

// Every triangle of a clamped group or one with prescribed components must be a face of a
// tetrahedron (an interior one too: a surface inside the body may be held): a triangle of no element
// would prescribe the nodes it happens to share with the body, in silence (a contact node held there
// changes the contact force). One pass over the tetrahedra for every such group, as for the loads.
void check_constraint_faces(const Mesh& mesh, const MeshRoles& roles) {
  std::vector<std::string> names = roles.clamped;
  names.insert(names.end(), roles.displaced.begin(), roles.displaced.end());
  std::vector<WantedFaces> groups;
  WantedFaces all;
  for (const auto& name : names) {
    const int tag = group_tag(mesh, name);
    WantedFaces wanted;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
      if (mesh.triangle_group[t] == tag) wanted[sorted(mesh.triangles[t])].push_back(t);
    for (const auto& [face, tris] : wanted) all[face].insert(all[face].end(), tris.begin(), tris.end());
    groups.push_back(std::move(wanted));
  }
  if (all.empty()) return;
  const FaceUse use = face_use(mesh, all);
  for (std::size_t k = 0; k < names.size(); ++k) {
    const std::string& name = names[k];
    const MisplacedTriangles found = misplaced_triangles(groups[k], use);
    if (!found.orphans.empty())
      throw InputError("group '" + name + "' (held by boundary.clamped or boundary.displacement): " +
                       std::to_string(found.orphans.size()) + " triangle(s) are not a face of any tetrahedron (tags " +
                       tag_list(file_tags(mesh, found.orphans)) +
                       "): a prescribed surface must be faces of the body's elements (gmsh saves only the elements "
                       "of physical groups: is every volume in a Physical Volume?)");
  }
}

// Initial penetration: the body — the nodes of its tetrahedra; a node no element uses is not part of
// it — must lie on or above the foundation plane z = 0.
void check_above_foundation(const Mesh& mesh, const MeshRoles& roles) {
  if (roles.contact.empty() || mesh.tets.empty()) return;
  const std::vector<char> in_body = nodes_of_tets(mesh);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  std::size_t deepest = static_cast<std::size_t>(mesh.tets[0][0]);
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v) {
    if (!in_body[v]) continue;
    lo = lo.cwiseMin(mesh.nodes[v]), hi = hi.cwiseMax(mesh.nodes[v]);
    if (mesh.nodes[v].z() < mesh.nodes[deepest].z()) deepest = v;
  }
  const double tol = kPenetrationRounding * (hi - lo).norm();
  if (!(mesh.nodes[deepest].z() < -tol)) return;
  Eigen::Vector3d at = roles.user_point ? roles.user_point(mesh.nodes[deepest]) : mesh.nodes[deepest];
  for (double& c : at) c = std::abs(c) > 1e-12 * (hi - lo).norm() ? c : 0.0;  // the turn's rounding
  throw InputError("the body reaches below the foundation plane (initial penetration): node " +
                   std::to_string(mesh.node_tags[deepest]) + " at (" + number(at.x()) + ", " + number(at.y()) + ", " +
                   number(at.z()) + ") lies " + number(-mesh.nodes[deepest].z()) +
                   " below it (the plane z = 0, or that of contact.plane_point / plane_normal); move the mesh or "
                   "the plane so that the contact face lies on or above it and the body above it");
}

// A clamp, prescribed displacement or load on a surface group that holds no triangles would act
// nowhere, silently (a gmsh "Surface In BoundingBox" selection that missed its face: the load vanished
// from the applied forces with no warning, while an empty contact group was refused).
void check_condition_groups_not_empty(const Mesh& mesh, const MeshRoles& roles) {
  std::map<int, std::size_t> triangles_in;
  for (const int tag : mesh.triangle_group) ++triangles_in[tag];
  const auto require = [&](const std::vector<std::string>& names, const std::string& what) {
    for (const auto& name : names)
      if (const int tag = group_tag(mesh, name); tag >= 0 && triangles_in[tag] == 0)
        throw InputError(what + " group '" + name +
                         "' has no triangles in the mesh (a physical surface without elements, e.g. a gmsh "
                         "'Surface In BoundingBox' selection that found no surface), so its condition would act "
                         "nowhere; fix the group in the mesh or remove it from the scene");
  };
  require(roles.clamped, "boundary.clamped");
  require(roles.displaced, "boundary.displacement");
  require(roles.loaded, "load (boundary.traction / pressure)");
}

// Constrained nodes that all lie on one line (or at one point) leave a rigid rotation free.
void check_constraints_hold(const Mesh& mesh, const MeshRoles& roles) {
  if (!roles.displaced.empty()) return;  // per-component conditions: require_rigid_motions_fixed decides
  std::set<int> nodes;
  std::string names;
  for (const auto& name : roles.clamped) {
    names += (names.empty() ? "'" : ", '") + name + "'";
    const int tag = group_tag(mesh, name);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
      if (mesh.triangle_group[t] == tag) nodes.insert(mesh.triangles[t].begin(), mesh.triangles[t].end());
  }
  if (nodes.empty()) return;  // reported where Γu is required
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int v : nodes) mean += mesh.nodes[v];
  mean /= static_cast<double>(nodes.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (int v : nodes) scatter += (mesh.nodes[v] - mean) * (mesh.nodes[v] - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  const Eigen::Vector3d ev = eig.eigenvalues();  // ascending
  const double scale = std::max(ev[2], 1e-300);
  if (ev[1] > 1e-12 * scale && ev[2] > 0) return;  // the nodes span a plane: no free motion
  const Eigen::Vector3d axis = eig.eigenvectors().col(2);
  const std::string at = "(" + number(mean.x()) + ", " + number(mean.y()) + ", " + number(mean.z()) + ")";
  if (!(ev[2] > 0))
    throw InputError("the constrained group(s) " + names + " hold a single point " + at +
                     ": the body can rotate freely about it; constrain a surface (three nodes not on one line)");
  throw InputError("the constrained nodes of " + names + " all lie on one line through " + at + " along (" +
                   number(axis.x()) + ", " + number(axis.y()) + ", " + number(axis.z()) +
                   "): the body can rotate freely about that axis; constrain a surface, not an edge");
}

}  // namespace

FacesAgainstTheBody faces_against_the_body(const Mesh& mesh) {
  if (body_parts(mesh).count() < 2) return {};  // one part cannot lie against another
  const std::vector<TetFace> faces = tet_faces(mesh);
  // Each boundary face's centre moved off the body, along its outward normal, by 1e-3 of its
  // tetrahedron's height over it: outside every tetrahedron unless another volume lies right there.
  std::vector<PointTree::Point> outside;  // labelled by their face's index in `faces`
  for (std::size_t k = 0; k < faces.size(); ++k) {
    if (!face_on_the_boundary(faces, k)) continue;
    const auto& t = mesh.tets[faces[k].tet];
    const Eigen::Vector3d &a = mesh.nodes[faces[k].nodes[0]], &b = mesh.nodes[faces[k].nodes[1]],
                          &c = mesh.nodes[faces[k].nodes[2]];
    const int apex = *std::find_if(t.begin(), t.end(), [&](int v) {
      return v != faces[k].nodes[0] && v != faces[k].nodes[1] && v != faces[k].nodes[2];
    });
    Eigen::Vector3d normal = (b - a).cross(c - a);
    if (normal.norm() == 0.0) continue;
    normal.normalize();
    double height = (mesh.nodes[apex] - a).dot(normal);
    if (height > 0) normal = -normal, height = -height;  // away from the apex: outward
    outside.push_back({(a + b + c) / 3.0 + 1e-3 * -height * normal, faces[k].tet, static_cast<std::uint32_t>(k)});
  }
  FacesAgainstTheBody out;
  std::vector<char> counted(faces.size(), 0);
  for_points_inside_other_tets(mesh, PointTree(std::move(outside)), 1e-9,
                               [&](const PointTree::Point& p, std::size_t holder) {
                                 if (counted[p.label]) return true;
                                 counted[p.label] = 1;
                                 if (out.faces++ == 0) {
                                   const TetFace& f = faces[p.label];
                                   for (int j = 0; j < 3; ++j) out.example_nodes[j] = mesh.node_tags[f.nodes[j]];
                                   out.example_against = mesh.tet_tags[holder];
                                 }
                                 return true;
                               });
  return out;
}

BlocksJoinedAtNodes blocks_joined_at_nodes(const Mesh& mesh) {
  int count = 0;
  const std::vector<int> block_of_tet = face_connected_blocks(mesh, count);
  BlocksJoinedAtNodes out;
  out.blocks = count - body_parts(mesh).count();
  if (out.blocks <= 0) return {};
  std::vector<std::size_t> tets(static_cast<std::size_t>(count), 0), joints(tets.size(), 0), first(tets.size(), 0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    if (tets[static_cast<std::size_t>(block_of_tet[t])]++ == 0) first[static_cast<std::size_t>(block_of_tet[t])] = t;
  for (const std::vector<int>& in : blocks_of_nodes(mesh, block_of_tet))
    if (in.size() > 1)
      for (const int b : in) ++joints[static_cast<std::size_t>(b)];
  std::size_t smallest = 0;
  for (std::size_t b = 1; b < tets.size(); ++b)
    if (joints[b] > 0 && (joints[smallest] == 0 || tets[b] < tets[smallest])) smallest = b;
  out.example_tets = tets[smallest];
  out.example_tet = mesh.tet_tags[first[smallest]];
  out.example_joints = joints[smallest];
  return out;
}

void check_mesh_meaning(const Mesh& mesh, const MeshRoles& roles) {
  check_group_names(mesh);
  check_condition_groups_not_empty(mesh, roles);
  check_duplicate_tets(mesh);
  {
    const std::vector<TetFace> faces = tet_faces(mesh);
    check_tets_do_not_overlap(mesh, faces);
    check_no_tet_holds_another_centre(mesh, faces, roles);
  }
  check_duplicate_triangles(mesh, roles);
  check_contact_faces(mesh, roles);
  check_load_faces(mesh, roles);
  check_above_foundation(mesh, roles);
  check_constraints_hold(mesh, roles);
  check_constraint_faces(mesh, roles);  // after: constraints on a line are named as such first
}

}  // namespace contact3d
