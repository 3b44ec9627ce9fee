#include "contact/contact_operator.hpp"

namespace contact3d {

ContactOperator make_contact_operator(const ContactFace& face, const Partition& partition, const DofMap& dofs,
                                      bool with_friction) {
  ContactOperator op;
  op.r = static_cast<int>(partition.cells.size());
  op.with_friction = with_friction;
  std::vector<Eigen::Triplet<double>> entries;
  const auto weights = cell_node_weights(face, partition);
  const MultiplierLayout layout = op.layout();
  op.offset = Eigen::VectorXd::Zero(op.rows());
  // Row `row` gets weight·u_c: on the free dof, or in the offset where u_c is prescribed.
  auto add = [&](int row, int node, int c, double weight) {
    if (const int d = dofs.dof(node, c); d >= 0)
      entries.emplace_back(row, d, weight);
    else
      op.offset[row] += weight * dofs.prescribed[3 * node + c];
  };
  for (int i = 0; i < op.r; ++i)
    for (const auto& [node, w] : weights[i]) {
      add(layout.normal(i), node, 2, -w);                 // v_n = -v_3
      op.offset[layout.normal(i)] -= w * face.gap[node];  // ∫_{R_i} (w_n − d) <= 0
      if (!with_friction) continue;
      add(layout.t1(i), node, 0, w);
      add(layout.t2(i), node, 1, w);
    }
  op.B.resize(op.rows(), dofs.n_free);
  op.B.setFromTriplets(entries.begin(), entries.end());
  op.B.makeCompressed();
  return op;
}

}  // namespace contact3d
