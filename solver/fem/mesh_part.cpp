#include "fem/mesh_part.hpp"

#include <algorithm>

namespace contact3d {

std::vector<int> split_nodes_by_dofs(const DofMap& dofs, int parts) {
  std::vector<int> split(static_cast<std::size_t>(parts) + 1, dofs.n_nodes);
  split[0] = 0;
  long long seen = 0;
  for (int v = 0, r = 1; v < dofs.n_nodes && r < parts; ++v) {
    for (int c = 0; c < 3; ++c) seen += dofs.dof(v, c) >= 0;
    if (seen * parts >= static_cast<long long>(dofs.n_free) * r) split[static_cast<std::size_t>(r++)] = v + 1;
  }
  return split;
}

MeshPart cut_mesh_part(const Mesh& mesh, const DofMap& dofs, const TetMaterials& materials, int first_node,
                       int last_node) {
  auto own = [&](int v) { return v >= first_node && v < last_node; };
  std::vector<int> tets, nodes;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const auto& t = mesh.tets[e];
    if (!(own(t[0]) || own(t[1]) || own(t[2]) || own(t[3]))) continue;
    tets.push_back(static_cast<int>(e));
    nodes.insert(nodes.end(), t.begin(), t.end());
  }
  for (int v = first_node; v < last_node; ++v) nodes.push_back(v);  // own nodes no tet uses
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  MeshPart part;
  part.mesh.nodes.reserve(nodes.size());
  part.dofs.n_nodes = static_cast<int>(nodes.size());
  part.dofs.n_free = dofs.n_free;
  part.dofs.free_index.reserve(3 * nodes.size());
  for (int v : nodes) {
    part.mesh.nodes.push_back(mesh.nodes[static_cast<std::size_t>(v)]);
    for (int c = 0; c < 3; ++c) part.dofs.free_index.push_back(dofs.dof(v, c));
  }
  auto local = [&](int v) { return static_cast<int>(std::lower_bound(nodes.begin(), nodes.end(), v) - nodes.begin()); };
  part.mesh.tets.reserve(tets.size());
  part.materials.reserve(tets.size());
  for (int e : tets) {
    const auto& t = mesh.tets[static_cast<std::size_t>(e)];
    part.mesh.tets.push_back({local(t[0]), local(t[1]), local(t[2]), local(t[3])});
    part.materials.push_back(materials[static_cast<std::size_t>(e)]);
  }
  part.first_node = local(first_node);
  part.last_node = local(first_node) + (last_node - first_node);
  return part;
}

}  // namespace contact3d
