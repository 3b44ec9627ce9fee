#include "model/resultant_forces.hpp"

#include <algorithm>
#include <cmath>

namespace contact3d {
namespace {

// The force below which the resultants are rounding: K·u for a displacement of size u_max on a body of
// extent L and stiffness E leaves about 1e-16·E·L·u_max where the body only moves rigidly (5e-16 on
// a steel block lifted 1 mm by its top, every force 1e-7 N, balance 1.02 by the largest of them).
constexpr double kRoundingShare = 1e-11;
double rounding_force(const Mesh& mesh, const TetMaterials& materials, const Eigen::VectorXd& u_nodes) {
  double young = 0;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) young = std::max(young, materials[t].young);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const auto& tet : mesh.tets)
    for (const int v : tet) {
      lo = lo.cwiseMin(mesh.nodes[static_cast<std::size_t>(v)]);
      hi = hi.cwiseMax(mesh.nodes[static_cast<std::size_t>(v)]);
    }
  const double extent = mesh.tets.empty() ? 0.0 : (hi - lo).norm();
  const double u_max = u_nodes.size() ? u_nodes.cwiseAbs().maxCoeff() : 0.0;
  return kRoundingShare * young * extent * u_max;
}

}  // namespace

ResultantForces resultant_forces(const Mesh& mesh, const DofMap& dofs, const TetMaterials& materials,
                                 const std::vector<Traction>& tractions, const BodyForce& body_force,
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
  double scale = std::max({out.applied.norm(), out.contact.norm(), rounding_force(mesh, materials, u_nodes)});
  for (const auto& r : out.reactions) {
    sum += r.force;
    scale = std::max(scale, r.force.norm());
  }
  out.balance = scale > 0 ? sum.norm() / scale : 0.0;
  return out;
}

}  // namespace contact3d
