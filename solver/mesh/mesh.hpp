// Mesh: the tetrahedral body and its tagged boundary triangles, as read from a gmsh MSH file
// or generated in memory. Node and element indices are 0-based positions in these vectors;
// the file's own tags are kept for messages a user can act on.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace contact3d {

// A gmsh physical group: a named set of elements of one dimension (2 = boundary, 3 = body).
struct PhysicalGroup {
  int dim = 0;
  int tag = 0;
  std::string name;
};

struct Mesh {
  std::vector<Eigen::Vector3d> nodes;
  std::vector<std::size_t> node_tags;  // file tag of each node (for messages)

  std::vector<std::array<int, 4>> tets;  // node indices
  std::vector<std::size_t> tet_tags;     // file element tag of each tet
  std::vector<int> tet_group;            // physical tag of each tet (0 if none)
  // A tet in more than one volume group (a gmsh volume in two physical groups, e.g. "core" and "all"):
  // (tet index, tag) for every group after the one tet_group holds.
  std::vector<std::pair<std::size_t, int>> tet_extra_groups;

  // Boundary triangles. A triangle that belongs to several physical groups appears once per group.
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::size_t> triangle_tags;
  std::vector<int> triangle_group;  // physical tag (0 if none)

  std::vector<PhysicalGroup> groups;

  // Read from second-order elements (10-node tets, 6-node triangles) by their corner nodes: the
  // same P1 mesh as gmsh's first order on the same vertices; the other nodes are dropped.
  bool read_by_corner_nodes = false;
  // Every tetrahedron came negatively oriented — a mirrored mesh (FreeFEM's movemesh3 with a
  // reflection, a CAD mirror) — and two nodes of each were swapped (orient_mirrored_mesh).
  bool reoriented_mirrored = false;

  // The group of dimension `dim` called `name` (an unnamed group also answers to its number,
  // "4"), or nullptr.
  const PhysicalGroup* find_group(std::string_view name, int dim) const;
  // "name (dim 2), name (dim 3), ..." for error messages.
  std::string describe_groups() const;
  // Indices of the triangles tagged with the named 2-D group (throws InputError naming the
  // available groups if the mesh has no such group).
  std::vector<int> triangles_of_group(std::string_view name) const;
  // Indices of the tetrahedra in the volume group with physical tag `tag` (tet_group and
  // tet_extra_groups), ascending.
  std::vector<std::size_t> tets_of_group(int tag) const;
};

// Whether each node is a vertex of some tetrahedron (a node no element uses is not part of the body).
std::vector<char> nodes_of_tets(const Mesh& mesh);
// The diagonal of the box around those nodes (0 for a mesh without tetrahedra).
double body_diagonal(const Mesh& mesh);

// The body's connected parts: tetrahedra that share a node are one part. of_node[v] is node v's part
// (0 … count() − 1, in the order of their first tetrahedron), −1 where no tetrahedron uses it.
struct BodyParts {
  std::vector<int> of_node;
  std::vector<int> tets;  // per part, its number of tetrahedra
  int count() const { return static_cast<int>(tets.size()); }
};
BodyParts body_parts(const Mesh& mesh);
// Tetrahedra that share a face (three nodes) in one block: block_of_tet[t] in 0 … count − 1. A part
// whose tetrahedra fall into several blocks has blocks joined only at nodes or along edges.
std::vector<int> face_connected_blocks(const Mesh& mesh, int& count);
// The blocks each node lies in, from face_connected_blocks (empty for a node no tetrahedron uses); a node
// in several is a joint between blocks.
std::vector<std::vector<int>> blocks_of_nodes(const Mesh& mesh, const std::vector<int>& block_of_tet);
// The root of `v`'s set in a union-find forest (path halving): parts of meshes and blocks of tetrahedra.
int find_part(std::vector<int>& parent, int v);

// The area of a triangle of node indices.
inline double triangle_area(const Mesh& mesh, const std::array<int, 3>& tri) {
  const auto& x = mesh.nodes;
  return 0.5 * (x[static_cast<std::size_t>(tri[1])] - x[static_cast<std::size_t>(tri[0])])
                   .cross(x[static_cast<std::size_t>(tri[2])] - x[static_cast<std::size_t>(tri[0])])
                   .norm();
}

// For each triangle (node triples, any order): the tetrahedron it is a face of, kNoTetrahedron where
// none is, kSeveralTetrahedra where two are (an interior face).
constexpr int kNoTetrahedron = -1, kSeveralTetrahedra = -2;
std::vector<int> tetrahedra_of_faces(const Mesh& mesh, const std::vector<std::array<int, 3>>& triangles);

// The body's boundary: the faces of exactly one tetrahedron, oriented outward (their normal by the
// right-hand rule points out of the body).
std::vector<std::array<int, 3>> boundary_faces(const Mesh& mesh);

// A mesh whose every tetrahedron has a negative volume is a mirror image, consistent in itself: its
// tets are turned positive by swapping their first two nodes (reoriented_mirrored). A mesh with
// tets of both signs is tangled and left as it is, for check_tet_orientation to refuse.
void orient_mirrored_mesh(Mesh& mesh);

// Drops the nodes that no tet or triangle uses (a second-order file's mid-edge nodes, read by the
// elements' corners) and renumbers the others in their order; node_tags follow, so messages still
// name the file's nodes.
void drop_unused_nodes(Mesh& mesh);

}  // namespace contact3d
