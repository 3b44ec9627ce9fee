// FaceDofs: the displacement on Γc as the fixed point sees it — (u1, u2, u3) at every node of a
// contact triangle, in the order the triangles first name them (`nodes`), the prescribed value at
// prescribed components (0 where clamped) — and the slip ‖u_t‖ at the contact nodes computed from it,
// the P1 interpolant of (5.7): a face node moved along the plane by a boundary.displacement slips.
#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "contact/contact_face.hpp"
#include "fem/dof_map.hpp"

namespace contact3d {

struct FaceDofs {
  std::vector<int> nodes;                          // mesh nodes of the face's triangles, first-seen order
  std::vector<int> dofs;                           // free dofs of those nodes, by (node, component)
  std::vector<int> slots;                          // position of dofs[k] in the face vector (3 per node)
  std::vector<int> slot_of_node;                   // mesh node -> first slot, or -1
  std::vector<std::pair<int, double>> prescribed;  // (slot, value) of the components held at a nonzero value

  FaceDofs(const ContactFace& face, const DofMap& dof_map, std::size_t n_mesh_nodes);
  std::size_t size() const { return 3 * nodes.size(); }

  // The face vector (3 per node) from values at `dofs`, the prescribed values in their slots.
  Eigen::VectorXd scatter(const Eigen::VectorXd& values) const;
  // ‖(u1, u2)‖ at face.nodes (the contact nodes) from a face vector.
  Eigen::VectorXd slip(const ContactFace& face, const Eigen::VectorXd& u_face) const;
};

}  // namespace contact3d
