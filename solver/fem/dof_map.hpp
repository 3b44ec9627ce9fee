// DofMap: numbering of the free displacement unknowns. Node v has components c = 0,1,2;
// a component is eliminated (Dirichlet u = 0, Γu) when v lies on a clamped triangle.
#pragma once

#include <vector>

#include "mesh/mesh.hpp"

namespace contact3d {

struct DofMap {
  int n_nodes = 0;
  int n_free = 0;
  std::vector<int> free_index;  // 3*node + c -> free dof index, or -1 if clamped
  std::vector<char> clamped_node;

  int dof(int node, int component) const { return free_index[3 * node + component]; }
};

// Clamps every node of the triangles in `clamped_groups` (all three components).
DofMap make_dof_map(const Mesh& mesh, const std::vector<std::string>& clamped_groups);

}  // namespace contact3d
