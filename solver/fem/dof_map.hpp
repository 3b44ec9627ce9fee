// DofMap: numbering of the free displacement unknowns. Node v has components c = 0,1,2 (x, y, z);
// a component is eliminated when it is prescribed: all three on a clamped group (u = 0, Γu),
// the named ones on a `[[boundary.displacement]]` group (symmetry planes, rollers, imposed
// displacement). Prescribed values enter the load as the lift −K_fc·u_c (assembly.hpp).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mesh/mesh.hpp"

namespace contact3d {

// Prescribed components on the nodes of a boundary group's triangles (unset = free): component c
// at node x is value[c] + gradient.row(c)·x, affine in position (a small rotation θ about z:
// gradient = θ[[0,-1,0],[1,0,0],[0,0,0]]); rows of components left free are zero.
struct PrescribedDisplacement {
  std::string group;
  std::array<std::optional<double>, 3> value;          // m, per component x, y, z
  Eigen::Matrix3d gradient = Eigen::Matrix3d::Zero();  // m/m

  double at(int component, const Eigen::Vector3d& x) const {
    return *value[component] + gradient.row(component).dot(x);
  }
};

struct DofMap {
  int n_nodes = 0;
  int n_free = 0;
  std::vector<int> free_index;       // 3*node + c -> free dof index, or -1 if prescribed
  std::vector<double> prescribed;    // 3*node + c -> the prescribed value (0 where free or clamped)
  std::vector<unsigned char> fixed;  // per node: bit c set when component c is prescribed
  std::vector<char> used;            // per node: 1 when a tetrahedron uses it (unused nodes are fixed at 0)
  // The conditions that prescribe components ("boundary.clamped 'wall'", ...), and for 3*node + c
  // the one that fixed it (the first one listed), or -1: where each reaction force is reported.
  std::vector<std::string> conditions;
  std::vector<int> fixed_by;

  int dof(int node, int component) const { return free_index[3 * node + component]; }
  bool fully_fixed(int node) const { return fixed[node] == 7; }
  bool has_nonzero_prescribed() const;
};

// Clamps every node of the triangles in `clamped_groups` (all three components) and prescribes
// the given components on the nodes of each displacement group. Free dofs are numbered node by
// node, ascending. Throws InputError when two conditions give one component different values
// (beyond rounding, 1e-12 of the larger, where an affine field is evaluated at a shared node).
DofMap make_dof_map(const Mesh& mesh, const std::vector<std::string>& clamped_groups,
                    const std::vector<PrescribedDisplacement>& displacements = {});

// The six rigid motions (translations, rotations about the centroid) at the free dofs, as
// orthonormal columns (n_free × 6): the near-null space of K. K annihilates them except in the rows
// next to prescribed components; algebraic multigrid for elasticity (PETSc's GAMG, hypre) builds its
// coarse spaces from them (the distributed backend attaches them to its matrix).
Eigen::MatrixXd rigid_body_modes(const Mesh& mesh, const DofMap& dofs);

// The rigid motions u(x) = t + ω × (x − centre)/size that the prescribed components leave free (K is
// singular exactly along them): the null space of the 6 × 6 Gram matrix of the prescribed rows, as
// orthonormal columns (t; ω), about the used nodes' centroid in coordinates scaled by their extent.
struct FreeRigidMotions {
  Eigen::Matrix<double, 6, Eigen::Dynamic> motions;  // 6 × k, k = 0 when K is regular
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double size = 1;
  int count() const { return static_cast<int>(motions.cols()); }
  // "a translation along (0, 0, 1)", "a rotation about the axis along … through …", for (t; ω).
  std::string describe(const Eigen::Matrix<double, 6, 1>& free_motion) const;
};
FreeRigidMotions free_rigid_motions(const Mesh& mesh, const DofMap& dofs);

// free_rigid_motions of one part on its own (about its centroid, scaled by its extent).
FreeRigidMotions free_rigid_motions(const Mesh& mesh, const DofMap& dofs, const BodyParts& parts, int part);
// Those motions at the free dofs (n_free × k).
Eigen::MatrixXd rigid_motion_field(const Mesh& mesh, const DofMap& dofs, const FreeRigidMotions& free);
// Zero-energy motions of K other than each part's rigid motions (`parts`: body_parts(mesh)): tetrahedra
// that share a face move as one rigid block, and blocks joined only at nodes or along a line of edges can
// turn against each other (a hinge, a ball joint), the prescribed components not holding them. A
// description of one such joint, or "" where there is none (or more than 200 blocks, not searched).
std::string find_mechanism(const Mesh& mesh, const DofMap& dofs, const BodyParts& parts);
// One part's motions at its free dofs, zero on the other parts (n_free × k).
Eigen::MatrixXd rigid_motion_field(const Mesh& mesh, const DofMap& dofs, const FreeRigidMotions& free,
                                   const BodyParts& parts, int part);

// The rigid motion that fits the prescribed values best (least squares over the prescribed
// components; none along the motions they leave free) as a nodal field (3 · n_nodes, 0 at unused
// nodes): the part of the displacement a prescribed approach imposes rigidly, e.g. a punch pushed
// down by u_z = −δ on its top. Zero where every prescribed value is 0 (clamps, symmetry planes).
Eigen::VectorXd prescribed_rigid_motion(const Mesh& mesh, const DofMap& dofs);

// Throws InputError, before anything is factorized, when the prescribed components leave a rigid
// motion of the body free (K would be singular), naming the motion: a translation along a
// direction or a rotation about an axis through a point.
void require_rigid_motions_fixed(const Mesh& mesh, const DofMap& dofs);

}  // namespace contact3d
