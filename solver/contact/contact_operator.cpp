#include "contact/contact_operator.hpp"

namespace contact3d {

ContactOperator make_contact_operator(const ContactFace& face, const Partition& partition,
                                      const DofMap& dofs, bool with_friction) {
  ContactOperator op;
  op.r = static_cast<int>(partition.cells.size());
  op.with_friction = with_friction;
  std::vector<Eigen::Triplet<double>> entries;
  const auto weights = cell_node_weights(face, partition);
  const MultiplierLayout layout = op.layout();
  for (int i = 0; i < op.r; ++i)
    for (const auto& [node, w] : weights[i]) {
      if (int d = dofs.dof(node, 2); d >= 0) entries.emplace_back(layout.normal(i), d, -w);  // v_n = -v_3
      if (!with_friction) continue;
      if (int d = dofs.dof(node, 0); d >= 0) entries.emplace_back(layout.t1(i), d, w);
      if (int d = dofs.dof(node, 1); d >= 0) entries.emplace_back(layout.t2(i), d, w);
    }
  op.B.resize(op.rows(), dofs.n_free);
  op.B.setFromTriplets(entries.begin(), entries.end());
  op.B.makeCompressed();
  return op;
}

}  // namespace contact3d
