#include "contact/face_dofs.hpp"

#include <cmath>

namespace contact3d {

FaceDofs::FaceDofs(const ContactFace& face, const DofMap& dof_map, std::size_t n_mesh_nodes)
    : slot_of_node(n_mesh_nodes, -1) {
  for (const auto& tri : face.triangles)
    for (int v : tri)
      if (slot_of_node[v] < 0) {
        slot_of_node[v] = static_cast<int>(3 * nodes.size());
        nodes.push_back(v);
      }
  for (std::size_t j = 0; j < nodes.size(); ++j)
    for (int c = 0; c < 3; ++c)
      if (const int d = dof_map.dof(nodes[j], c); d >= 0) {
        dofs.push_back(d);
        slots.push_back(static_cast<int>(3 * j) + c);
      } else if (const std::size_t i = 3 * static_cast<std::size_t>(nodes[j]) + c;
                 i < dof_map.prescribed.size() && dof_map.prescribed[i] != 0) {
        prescribed.emplace_back(static_cast<int>(3 * j) + c, dof_map.prescribed[i]);
      }
}

Eigen::VectorXd FaceDofs::scatter(const Eigen::VectorXd& values) const {
  Eigen::VectorXd u_face = Eigen::VectorXd::Zero(size());
  for (std::size_t k = 0; k < slots.size(); ++k) u_face[slots[k]] = values[k];
  for (const auto& [slot, value] : prescribed) u_face[slot] = value;
  return u_face;
}

Eigen::VectorXd FaceDofs::slip(const ContactFace& face, const Eigen::VectorXd& u_face) const {
  Eigen::VectorXd phi(face.nodes.size());
  for (std::size_t k = 0; k < face.nodes.size(); ++k) {
    const int p = slot_of_node[face.nodes[k]];
    phi[k] = std::hypot(u_face[p], u_face[p + 1]);
  }
  return phi;
}

}  // namespace contact3d
