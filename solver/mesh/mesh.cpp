#include "mesh/mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>

#include "base/errors.hpp"

namespace contact3d {

const PhysicalGroup* Mesh::find_group(std::string_view name, int dim) const {
  for (const auto& g : groups)
    if (g.dim == dim && g.name == name) return &g;
  // An unnamed group (gmsh's physical groups without a name) by its number: "4".
  if (!name.empty() && name.find_first_not_of("0123456789") == std::string_view::npos && name.size() < 10)
    for (const auto& g : groups)
      if (g.dim == dim && g.name.empty() && std::to_string(g.tag) == name) return &g;
  return nullptr;
}

std::string Mesh::describe_groups() const {
  if (groups.empty()) return "(the mesh has no physical groups)";
  std::string out;
  for (const auto& g : groups) {
    if (!out.empty()) out += ", ";
    // An unnamed group as a scene names it, by its number ('4'), not as "unnamed 4".
    out += g.name.empty() ? "'" + std::to_string(g.tag) + "' (unnamed, dim " + std::to_string(g.dim) + ")"
                          : "'" + g.name + "' (dim " + std::to_string(g.dim) + ")";
  }
  return out;
}

void orient_mirrored_mesh(Mesh& mesh) {
  std::size_t negative = 0;
  for (const auto& t : mesh.tets) {
    const Eigen::Vector3d& a = mesh.nodes[t[0]];
    const double six_volume = (mesh.nodes[t[1]] - a).dot((mesh.nodes[t[2]] - a).cross(mesh.nodes[t[3]] - a));
    if (six_volume > 0) return;  // at least one positive: not a mirror image
    negative += six_volume < 0;
  }
  if (negative == 0) return;
  for (auto& t : mesh.tets) std::swap(t[0], t[1]);
  mesh.reoriented_mirrored = true;
}

std::vector<int> Mesh::triangles_of_group(std::string_view name) const {
  const PhysicalGroup* g = find_group(name, 2);
  if (!g)
    throw InputError("the mesh has no surface physical group '" + std::string(name) +
                     "'; its groups are: " + describe_groups());
  std::vector<int> out;
  for (std::size_t i = 0; i < triangles.size(); ++i)
    if (triangle_group[i] == g->tag) out.push_back(static_cast<int>(i));
  return out;
}

std::vector<std::size_t> Mesh::tets_of_group(int tag) const {
  std::vector<std::size_t> out;
  for (std::size_t e = 0; e < tet_group.size(); ++e)
    if (tet_group[e] == tag) out.push_back(e);
  for (const auto& [e, t] : tet_extra_groups)
    if (t == tag) out.push_back(e);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<char> nodes_of_tets(const Mesh& mesh) {
  std::vector<char> used(mesh.nodes.size(), 0);
  for (const auto& t : mesh.tets)
    for (const int v : t) used[static_cast<std::size_t>(v)] = 1;
  return used;
}

double body_diagonal(const Mesh& mesh) {
  const std::vector<char> in_body = nodes_of_tets(mesh);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
    if (in_body[v]) lo = lo.cwiseMin(mesh.nodes[v]), hi = hi.cwiseMax(mesh.nodes[v]);
  return mesh.tets.empty() ? 0.0 : (hi - lo).norm();
}

void drop_unused_nodes(Mesh& mesh) {
  std::vector<int> new_index(mesh.nodes.size(), -1);
  for (const auto& t : mesh.tets)
    for (int v : t) new_index[static_cast<std::size_t>(v)] = 0;
  for (const auto& t : mesh.triangles)
    for (int v : t) new_index[static_cast<std::size_t>(v)] = 0;
  std::size_t kept = 0;
  for (std::size_t v = 0; v < new_index.size(); ++v) {
    if (new_index[v] < 0) continue;
    new_index[v] = static_cast<int>(kept);
    mesh.nodes[kept] = mesh.nodes[v];
    if (v < mesh.node_tags.size()) mesh.node_tags[kept] = mesh.node_tags[v];
    ++kept;
  }
  mesh.nodes.resize(kept);
  if (mesh.node_tags.size() > kept) mesh.node_tags.resize(kept);
  for (auto& t : mesh.tets)
    for (int& v : t) v = new_index[static_cast<std::size_t>(v)];
  for (auto& t : mesh.triangles)
    for (int& v : t) v = new_index[static_cast<std::size_t>(v)];
}

std::vector<int> tetrahedra_of_faces(const Mesh& mesh, const std::vector<std::array<int, 3>>& triangles) {
  const auto sorted = [](std::array<int, 3> t) {
    std::sort(t.begin(), t.end());
    return t;
  };
  std::map<std::array<int, 3>, int> tet_of;  // sorted face -> its tetrahedron
  for (const auto& t : triangles) tet_of.emplace(sorted(t), kNoTetrahedron);
  for (std::size_t e = 0; e < mesh.tets.size(); ++e)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> face{};
      for (int a = 0, k = 0; a < 4; ++a)
        if (a != skip) face[k++] = mesh.tets[e][a];
      if (auto it = tet_of.find(sorted(face)); it != tet_of.end())
        it->second = it->second == kNoTetrahedron ? static_cast<int>(e) : kSeveralTetrahedra;
    }
  std::vector<int> out;
  out.reserve(triangles.size());
  for (const auto& t : triangles) out.push_back(tet_of[sorted(t)]);
  return out;
}

std::vector<std::array<int, 3>> boundary_faces(const Mesh& m) {
  // Every tet's four faces as seen from it (outward), sorted by their node triples: a boundary face
  // is one whose triple appears once. (Sorting, not a map: a million tetrahedra in a fraction of a second.)
  static const int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  struct Face {
    std::array<int, 3> key, outward;
  };
  std::vector<Face> faces;
  faces.reserve(4 * m.tets.size());
  for (const auto& t : m.tets)
    for (const auto& lf : kFace) {
      Face f{{}, {t[lf[0]], t[lf[1]], t[lf[2]]}};
      f.key = f.outward;
      std::sort(f.key.begin(), f.key.end());
      faces.push_back(f);
    }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) { return a.key < b.key; });
  std::vector<std::array<int, 3>> out;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j == i + 1) out.push_back(faces[i].outward);
    i = j;
  }
  return out;
}

int find_part(std::vector<int>& parent, int v) {
  while (parent[static_cast<std::size_t>(v)] != v)
    v = parent[static_cast<std::size_t>(v)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(v)])];
  return v;
}

BodyParts body_parts(const Mesh& mesh) {
  const int n = static_cast<int>(mesh.nodes.size());
  std::vector<int> parent(static_cast<std::size_t>(n));
  for (int v = 0; v < n; ++v) parent[static_cast<std::size_t>(v)] = v;
  for (const auto& t : mesh.tets)
    for (int k = 1; k < 4; ++k) {
      const int a = find_part(parent, t[0]), b = find_part(parent, t[k]);
      if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
    }
  BodyParts parts;
  parts.of_node.assign(static_cast<std::size_t>(n), -1);
  std::vector<int> number_of_root(static_cast<std::size_t>(n), -1);
  for (const auto& t : mesh.tets) {
    int& number = number_of_root[static_cast<std::size_t>(find_part(parent, t[0]))];
    if (number < 0) {
      number = parts.count();
      parts.tets.push_back(0);
    }
    ++parts.tets[static_cast<std::size_t>(number)];
    for (int v : t) parts.of_node[static_cast<std::size_t>(v)] = number;
  }
  return parts;
}

// By union-find over the faces, bucketed by their smallest node (a counting sort), so only the few faces
// around a node are compared: linear in the mesh.
std::vector<int> face_connected_blocks(const Mesh& mesh, int& count) {
  const int n = static_cast<int>(mesh.tets.size());
  std::vector<int> parent(static_cast<std::size_t>(n));
  for (int t = 0; t < n; ++t) parent[static_cast<std::size_t>(t)] = t;
  struct Face {
    std::int64_t rest;  // the two larger nodes
    int tet;
    bool operator<(const Face& o) const { return rest < o.rest; }
  };
  std::vector<int> start(mesh.nodes.size() + 1, 0);
  const auto face_of = [&](int t, int skip) {
    std::array<int, 3> f{};
    for (int k = 0, j = 0; k < 4; ++k)
      if (k != skip)
        f[static_cast<std::size_t>(j++)] = mesh.tets[static_cast<std::size_t>(t)][static_cast<std::size_t>(k)];
    std::sort(f.begin(), f.end());
    return f;
  };
  for (int t = 0; t < n; ++t)
    for (int skip = 0; skip < 4; ++skip) ++start[static_cast<std::size_t>(face_of(t, skip)[0]) + 1];
  for (std::size_t v = 1; v < start.size(); ++v) start[v] += start[v - 1];
  std::vector<Face> faces(4 * static_cast<std::size_t>(n));
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int t = 0; t < n; ++t)
    for (int skip = 0; skip < 4; ++skip) {
      const std::array<int, 3> f = face_of(t, skip);
      faces[static_cast<std::size_t>(fill[static_cast<std::size_t>(f[0])]++)] = {
          static_cast<std::int64_t>(f[1]) << 32 | static_cast<std::uint32_t>(f[2]), t};
    }
  for (std::size_t v = 0; v + 1 < start.size(); ++v) {
    const auto first = faces.begin() + start[v], last = faces.begin() + start[v + 1];
    std::sort(first, last);
    for (auto it = first; it != last && it + 1 != last; ++it)
      if (it->rest == (it + 1)->rest) {
        const int a = find_part(parent, it->tet), b = find_part(parent, (it + 1)->tet);
        if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
      }
  }
  std::vector<int> of_tet(static_cast<std::size_t>(n)), number(static_cast<std::size_t>(n), -1);
  count = 0;
  for (int t = 0; t < n; ++t) {
    int& b = number[static_cast<std::size_t>(find_part(parent, t))];
    if (b < 0) b = count++;
    of_tet[static_cast<std::size_t>(t)] = b;
  }
  return of_tet;
}

std::vector<std::vector<int>> blocks_of_nodes(const Mesh& mesh, const std::vector<int>& block_of_tet) {
  std::vector<std::vector<int>> of_node(mesh.nodes.size());
  for (std::size_t t = 0; t < mesh.tets.size(); ++t)
    for (const int v : mesh.tets[t]) {
      std::vector<int>& in = of_node[static_cast<std::size_t>(v)];
      if (std::find(in.begin(), in.end(), block_of_tet[t]) == in.end()) in.push_back(block_of_tet[t]);
    }
  return of_node;
}

}  // namespace contact3d
