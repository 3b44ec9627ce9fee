#include "qp/reduced_cg.hpp"

namespace contact3d {
namespace {

// diag(Dᵀ diag(Q) D) + shift: a sliding direction's weights spread over two of Q's diagonal entries
// (the coupling Q_ab between its two tangents is left out; it is a preconditioner).
Eigen::VectorXd reduced_diagonal(const BoxDiscQP& qp, const std::vector<Direction>& d) {
  const Eigen::VectorXd q = qp.diagonal();
  Eigen::VectorXd diagonal(static_cast<Eigen::Index>(d.size()));
  for (std::size_t j = 0; j < d.size(); ++j) {
    const Direction& e = d[j];
    double v = e.w_a * e.w_a * q[e.a] + e.shift;
    if (e.b >= 0) v += e.w_b * e.w_b * q[e.b];
    diagonal[static_cast<Eigen::Index>(j)] = v > 0 ? v : 1.0;
  }
  return diagonal;
}

}  // namespace

ReducedCgResult solve_reduced_cg(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::VectorXd& b,
                                 double tolerance, int max_iterations, Eigen::VectorXd& y) {
  ReducedCgResult result;
  Eigen::VectorXd r = b;
  if (y.size() == b.size()) {
    r -= reduced_product(qp, d, y);
    ++result.iterations;
  } else {
    y = Eigen::VectorXd::Zero(b.size());
  }
  result.residual = r.norm();
  if (result.residual <= tolerance) {
    result.converged = true;
    return result;
  }
  const Eigen::VectorXd inverse_diagonal = reduced_diagonal(qp, d).cwiseInverse();
  Eigen::VectorXd z = r.cwiseProduct(inverse_diagonal);
  Eigen::VectorXd p = z;
  double rz = r.dot(z);
  while (result.iterations < max_iterations) {
    const Eigen::VectorXd Ap = reduced_product(qp, d, p);
    ++result.iterations;
    const double curvature = p.dot(Ap);
    if (!(curvature > 0)) break;  // not positive definite in this direction (rounding): stop here
    const double alpha = rz / curvature;
    y += alpha * p;
    r -= alpha * Ap;
    result.residual = r.norm();
    if (result.residual <= tolerance) {
      result.converged = true;
      break;
    }
    z = r.cwiseProduct(inverse_diagonal);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return result;
}

}  // namespace contact3d
