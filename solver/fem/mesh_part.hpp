// MeshPart: what one rank of the distributed backend needs to assemble the columns of K for its
// nodes (assemble_stiffness_columns): the tets around those nodes and the nodes of those tets, in
// the whole mesh's node order (so the rank's own nodes stay consecutive and each column's rows come
// out sorted), each tet's material, and the whole mesh's dof numbers. Rank 0 cuts one part per
// rank and sends it, so no other rank holds the whole mesh.
#pragma once

#include <vector>

#include "fem/dof_map.hpp"
#include "fem/elasticity.hpp"
#include "mesh/mesh.hpp"

namespace contact3d {

struct MeshPart {
  Mesh mesh;                          // nodes and tets only
  DofMap dofs;                        // n_nodes = the part's, n_free = the whole mesh's; free_index only
  std::vector<Material> materials;    // per tet of the part
  int first_node = 0, last_node = 0;  // the rank's own nodes, in the part's numbering
};

// Node ranges for `parts` ranks with about n_free / parts free dofs each: part r owns the nodes
// [split[r], split[r + 1]) (split[0] = 0, split[parts] = n_nodes; a range may be empty).
std::vector<int> split_nodes_by_dofs(const DofMap& dofs, int parts);

// The part for the nodes [first_node, last_node) of the whole mesh (one pass over its tets).
MeshPart cut_mesh_part(const Mesh& mesh, const DofMap& dofs, const TetMaterials& materials, int first_node,
                       int last_node);

}  // namespace contact3d
