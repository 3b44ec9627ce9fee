#include "model/resultant_forces.hpp"

#include <algorithm>

namespace contact3d {

ResultantForces resultant_forces(const Mesh& mesh, const DofMap& dofs, const TetMaterials& materials,
                                 const std::vector<Traction>& tractions, const Eigen::Vector3d& body_force,
                                 const Eigen::VectorXd& u_nodes, const Eigen::SparseMatrix<double>& B,
                                 const Eigen::VectorXd& lambda) {
  ResultantForces out;
  const DofMap none = make_dof_map(mesh, {});  // every used node free: the loads at all nodes
  const Eigen::VectorXd loads = assemble_load(mesh, none, tractions, body_force);
  for (int v = 0; v < none.n_nodes; ++v)
    for (int c = 0; c < 3; ++c)
      if (const int d = none.dof(v, c); d >= 0) out.applied[c] += loads[d];
  if (B.rows() > 0 && lambda.size() == B.rows()) {
    const Eigen::VectorXd on_body = -(B.transpose() * lambda);
    for (int i = 0; i < 3 * dofs.n_nodes; ++i)
      if (const int d = dofs.free_index[i]; d >= 0) out.contact[i % 3] += on_body[d];
  }
  out.reactions = reaction_forces(dofs, internal_minus_external(mesh, materials, tractions, body_force, u_nodes));
  Eigen::Vector3d sum = out.applied + out.contact;
  double scale = std::max(out.applied.norm(), out.contact.norm());
  for (const auto& r : out.reactions) {
    sum += r.force;
    scale = std::max(scale, r.force.norm());
  }
  out.balance = scale > 0 ? sum.norm() / scale : 0.0;
  return out;
}

}  // namespace contact3d
