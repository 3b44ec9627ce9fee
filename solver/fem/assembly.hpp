// Global P1 elasticity system on the free dofs: stiffness K (symmetric, both triangles stored)
// and load vector f from surface loads on named groups (tractions affine in position, normal
// pressures), a constant body force and the lift −K_fc·u_c of prescribed displacements; the
// reaction forces at the prescribed components once u is known.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "fem/dof_map.hpp"
#include "fem/elasticity.hpp"
#include "mesh/mesh.hpp"

namespace contact3d {

// A surface load on a boundary group: t(x) = value + gradient·x (Pa; affine in position, e.g. a
// torsion gradient = τ[[0,-1,0],[1,0,0],[0,0,0]]) plus a normal pressure p(x) = pressure +
// pressure_gradient·x (Pa, pushing into the body, e.g. a hydrostatic ρg·depth: adds −p·n with n the
// body's outward normal, so it follows curved faces).
struct Traction {
  std::string group;
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
  Eigen::Matrix3d gradient = Eigen::Matrix3d::Zero();           // Pa/m
  double pressure = 0;                                          // Pa
  Eigen::Vector3d pressure_gradient = Eigen::Vector3d::Zero();  // Pa/m
  // [[boundary.force]] (N): the load's resultant, spread uniformly over the group's area as value =
  // total_force / area by resolve_total_forces (model/scene.hpp) before the solve reads `value`.
  std::optional<Eigen::Vector3d> total_force;
  bool given_as_force = false;  // a [[boundary.force]] entry, resolved or not

  bool has_pressure() const { return pressure != 0 || !pressure_gradient.isZero(); }
  // The scene's table the load came from, for messages: "boundary.traction", "boundary.pressure", "boundary.force".
  const char* scene_key() const {
    return given_as_force ? "boundary.force" : has_pressure() ? "boundary.pressure" : "boundary.traction";
  }
};

struct ElasticSystem {
  Eigen::SparseMatrix<double> K;  // n_free x n_free
  Eigen::VectorXd f;              // n_free
};

// Throws InputError naming the tets (file tags) that are inverted or degenerate.
void check_tet_orientation(const Mesh& mesh);

Eigen::SparseMatrix<double> assemble_stiffness(const Mesh& mesh, const DofMap& dofs, const TetMaterials& material);
// The same matrix by plain triplet assembly (the reference the fast path is tested against,
// and the fallback for dof maps without the node-block layout of make_dof_map).
Eigen::SparseMatrix<double> assemble_stiffness_triplets(const Mesh& mesh, const DofMap& dofs,
                                                        const TetMaterials& material);
// The columns of K for the free dofs of nodes [first_node, last_node) — one rank's share when the
// distributed backend assembles K on every rank — as an n_free × (their dofs) matrix; the block's
// column j is K's column first_free_dof(dofs, first_node) + j. The dofs must increase node by node
// (make_dof_map's numbering) and be consecutive over the range; `mesh` may be just the tets around
// the range, with the whole mesh's dof numbers and n_free. Over all nodes it is assemble_stiffness.
Eigen::SparseMatrix<double> assemble_stiffness_columns(const Mesh& mesh, const DofMap& dofs,
                                                       const TetMaterials& material, int first_node, int last_node);
// The first free dof of the nodes from `node` on (n_free when there is none).
int first_free_dof(const DofMap& dofs, int node);

// The graph of K's node blocks, for ordering K without forming it: one vertex per node with a free
// dof, in node order, so vertex v's dofs are first_dof[v] .. first_dof[v + 1] − 1; v is adjacent to
// adj[adj_start[v] .. adj_start[v + 1]) (sorted, v included): the vertices sharing a tet with it.
struct NodeGraph {
  std::vector<int> first_dof, adj_start, adj;
};
NodeGraph free_node_graph(const Mesh& mesh, const DofMap& dofs);

// K·w element by element, K never formed (for a process that has handed K to a distributed
// factorization and freed it); equals assemble_stiffness(mesh, dofs, material) * w.
Eigen::VectorXd apply_stiffness(const Mesh& mesh, const DofMap& dofs, const TetMaterials& material,
                                const Eigen::VectorXd& w);
// K's diagonal entries at the free dofs `free_dofs`, from the elements that touch their nodes only
// (K never formed); equal to assemble_stiffness(mesh, dofs, material).diagonal() there.
std::vector<double> stiffness_diagonal_at(const Mesh& mesh, const DofMap& dofs, const TetMaterials& material,
                                          const std::vector<int>& free_dofs);
// The external loads at the free dofs (tractions integrated exactly for affine t). Throws
// InputError for a pressure on a group that is not a boundary face of the body.
Eigen::VectorXd assemble_load(const Mesh& mesh, const DofMap& dofs, const std::vector<Traction>& tractions,
                              const BodyForce& body_force);
// −K_fc·u_c: what the prescribed displacements add to the free dofs' load (zero for clamps).
Eigen::VectorXd assemble_lift(const Mesh& mesh, const DofMap& dofs, const TetMaterials& material);

// Full nodal displacement (3 per node, prescribed values where fixed) from the free-dof vector.
Eigen::VectorXd expand_to_nodes(const DofMap& dofs, const Eigen::VectorXd& u_free);

// r = K·u − f_ext per node and component for the whole displacement u (3 per node). Equilibrium
// reads K·u = f_ext + f_contact + f_support, and f_contact vanishes at prescribed components, so
// there r is the force the support exerts on the body.
Eigen::VectorXd internal_minus_external(const Mesh& mesh, const TetMaterials& material,
                                        const std::vector<Traction>& tractions, const BodyForce& body_force,
                                        const Eigen::VectorXd& u_nodes);

// The force each prescribing condition exerts on the body (N): r summed over the components it
// fixes (a component fixed by two conditions counts for the first one listed).
struct ReactionForce {
  std::string condition;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
};
std::vector<ReactionForce> reaction_forces(const DofMap& dofs, const Eigen::VectorXd& residual);

}  // namespace contact3d
