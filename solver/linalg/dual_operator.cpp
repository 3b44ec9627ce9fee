#include "linalg/dual_operator.hpp"

#include <algorithm>

namespace contact3d {

DualOperator make_dual_operator(const SparseCholesky& K, const Eigen::SparseMatrix<double>& B,
                                const Eigen::VectorXd& f, int block_columns) {
  DualOperator op;
  const int m = static_cast<int>(B.rows());
  op.u_free = K.solve(f);
  op.h = B * op.u_free;
  op.solves = 1;
  op.Q.resize(m, m);
  const Eigen::SparseMatrix<double> Bt = B.transpose();
  for (int j0 = 0; j0 < m; j0 += block_columns) {
    const int cols = std::min(block_columns, m - j0);
    const Eigen::MatrixXd rhs = Eigen::MatrixXd(Bt.middleCols(j0, cols));
    const Eigen::MatrixXd X = K.solve(rhs);
    op.Q.middleCols(j0, cols) = B * X;
    op.solves += cols;
  }
  op.Q = 0.5 * (op.Q + op.Q.transpose()).eval();
  return op;
}

double estimate_norm(const Eigen::MatrixXd& Q, int iterations) {
  if (Q.rows() == 0) return 0;
  Eigen::VectorXd x = Eigen::VectorXd::Ones(Q.rows()).normalized();
  double lambda = 0;
  for (int k = 0; k < iterations; ++k) {
    const Eigen::VectorXd y = Q * x;
    const double norm = y.norm();
    if (norm == 0) return 0;
    lambda = x.dot(y);
    x = y / norm;
  }
  return std::max(lambda, (Q * x).norm());
}

}  // namespace contact3d
