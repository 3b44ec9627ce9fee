// ResultantForces: the forces on the body as a whole, summed from the solution — the applied loads,
// the contact force, the reaction of every prescribing condition (clamp, displacement group) — and
// how well they balance (a check of the solve that needs no reference solution).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "fem/assembly.hpp"
#include "fem/dof_map.hpp"
#include "mesh/mesh.hpp"

namespace contact3d {

struct ResultantForces {
  Eigen::Vector3d applied = Eigen::Vector3d::Zero();  // tractions, pressures and body force (N)
  // The foundation's force on the body, −𝔹ᵀλ summed over the free components (where a contact
  // node's component is prescribed, its share of the contact force is in that condition's reaction).
  Eigen::Vector3d contact = Eigen::Vector3d::Zero();
  // The rest of ∫λ over the cells: the share of the contact force at prescribed components of contact
  // nodes (a clamped edge of Γc, a roller on it), counted in those conditions' reactions, so that
  // contact + contact_at_held_nodes is the whole contact force (the run report's and contact_force's).
  Eigen::Vector3d contact_at_held_nodes = Eigen::Vector3d::Zero();
  std::vector<ReactionForce> reactions;  // the supports' forces on the body (N)
  // |applied + contact + Σ reactions| / max(|applied|, |contact|, max |reaction|, rounding force): 0 in
  // exact equilibrium; of the order of the solver's tolerances otherwise. The rounding force,
  // 1e-11·E·L·max|u|, keeps a body that only moves rigidly (every force rounding) from reading ~1.
  double balance = 0;
};

// `u_nodes` the whole displacement (3 per node), `B`/`lambda` the contact operator and multipliers
// (empty without contact).
ResultantForces resultant_forces(const Mesh& mesh, const DofMap& dofs, const TetMaterials& materials,
                                 const std::vector<Traction>& tractions, const BodyForce& body_force,
                                 const Eigen::VectorXd& u_nodes, const Eigen::SparseMatrix<double>& B,
                                 const Eigen::VectorXd& lambda);

}  // namespace contact3d
