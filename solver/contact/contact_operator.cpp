#include "contact/contact_operator.hpp"

#include <cmath>

#include <Eigen/SparseCholesky>

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

std::vector<int> dependent_rows(const Eigen::SparseMatrix<double>& B) {
  std::vector<int> rows;
  if (B.rows() == 0) return rows;
  // Rows scaled to unit length, so that a small cell's short row is not taken for a dependent one;
  // a shift of 1e-14 keeps every pivot positive (an exactly zero one would stop the factorization)
  // and far below the 1e-11 that marks a dependent row.
  // The rows' lengths in one pass over the nonzeros: B.row(i) of a column-major 𝔹 walks every column
  // (rows × free dofs: 2.3 s at 10 000 multipliers, once every route checked (5.1) here).
  const Eigen::VectorXd squared = B.cwiseAbs2() * Eigen::VectorXd::Ones(B.cols());
  Eigen::VectorXd inverse_length(B.rows());
  for (Eigen::Index i = 0; i < B.rows(); ++i) {
    const double length = std::sqrt(squared[i]);
    inverse_length[i] = length > 0 ? 1 / length : 0.0;  // an empty row: a zero pivot, dependent
  }
  const Eigen::SparseMatrix<double> unit_rows = inverse_length.asDiagonal() * B;
  Eigen::SparseMatrix<double> gram = unit_rows * unit_rows.transpose();
  for (Eigen::Index i = 0; i < gram.rows(); ++i) gram.coeffRef(i, i) += 1e-14;
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(gram);
  const Eigen::VectorXd d = ldlt.vectorD();
  const auto& row_of_pivot = ldlt.permutationPinv().indices();  // pivot k is row Pinv[k] of the Gram matrix
  const bool factored = ldlt.info() == Eigen::Success;          // else its pivots say nothing: every row is suspect
  for (Eigen::Index k = 0; k < d.size(); ++k)
    if (!factored || !(d[k] > 1e-11)) rows.push_back(row_of_pivot[k]);
  return rows;
}

}  // namespace contact3d
