#include "fem/dof_map.hpp"

namespace contact3d {

DofMap make_dof_map(const Mesh& mesh, const std::vector<std::string>& clamped_groups) {
  DofMap map;
  map.n_nodes = static_cast<int>(mesh.nodes.size());
  map.clamped_node.assign(map.n_nodes, 0);
  for (const auto& name : clamped_groups)
    for (int t : mesh.triangles_of_group(name))
      for (int v : mesh.triangles[t]) map.clamped_node[v] = 1;
  // Nodes not used by any tet carry no stiffness: treat them as fixed so K stays regular.
  std::vector<char> used(map.n_nodes, 0);
  for (const auto& t : mesh.tets)
    for (int v : t) used[v] = 1;
  map.free_index.assign(3 * map.n_nodes, -1);
  for (int v = 0; v < map.n_nodes; ++v)
    if (!map.clamped_node[v] && used[v])
      for (int c = 0; c < 3; ++c) map.free_index[3 * v + c] = map.n_free++;
  return map;
}

}  // namespace contact3d
