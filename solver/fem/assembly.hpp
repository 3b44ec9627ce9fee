// Global P1 elasticity system on the free dofs: stiffness K (symmetric, both triangles stored)
// and load vector f from surface tractions on named groups and a constant body force.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "fem/dof_map.hpp"
#include "fem/elasticity.hpp"
#include "mesh/mesh.hpp"

namespace contact3d {

struct Traction {
  std::string group;        // surface physical group
  Eigen::Vector3d value;    // Pa, constant over the group
};

struct ElasticSystem {
  Eigen::SparseMatrix<double> K;  // n_free x n_free
  Eigen::VectorXd f;              // n_free
};

// Throws InputError naming the tets (file tags) that are inverted or degenerate.
void check_tet_orientation(const Mesh& mesh);

Eigen::SparseMatrix<double> assemble_stiffness(const Mesh& mesh, const DofMap& dofs,
                                               const Material& material);
// The same matrix by plain triplet assembly (the reference the fast path is tested against,
// and the fallback for dof maps without the node-block layout of make_dof_map).
Eigen::SparseMatrix<double> assemble_stiffness_triplets(const Mesh& mesh, const DofMap& dofs,
                                                        const Material& material);
Eigen::VectorXd assemble_load(const Mesh& mesh, const DofMap& dofs,
                              const std::vector<Traction>& tractions,
                              const Eigen::Vector3d& body_force);

// Full nodal displacement (3 per node, clamped = 0) from the free-dof vector.
Eigen::VectorXd expand_to_nodes(const DofMap& dofs, const Eigen::VectorXd& u_free);

}  // namespace contact3d
