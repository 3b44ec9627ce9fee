#include "fem/elasticity.hpp"

#include <Eigen/Dense>

namespace contact3d {

Matrix6d hooke_matrix(const Material& m) {
  const double E = m.young, nu = m.poisson;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  const double mu = E / (2 * (1 + nu));
  Matrix6d D = Matrix6d::Zero();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) D(i, j) = lambda;
    D(i, i) += 2 * mu;
    D(i + 3, i + 3) = mu;
  }
  return D;
}

double tet_volume(const TetCoords& x) { return (x[1] - x[0]).dot((x[2] - x[0]).cross(x[3] - x[0])) / 6.0; }

Matrix6x12d strain_matrix(const TetCoords& x) {
  // Gradients of the barycentric hat functions: rows of the inverse Jacobian.
  Eigen::Matrix3d J;
  for (int k = 0; k < 3; ++k) J.col(k) = x[k + 1] - x[0];
  const Eigen::Matrix3d Jinv = J.inverse();  // row k = grad of hat k+1
  std::array<Eigen::Vector3d, 4> grad;
  for (int k = 0; k < 3; ++k) grad[k + 1] = Jinv.row(k).transpose();
  grad[0] = -(grad[1] + grad[2] + grad[3]);
  Matrix6x12d B = Matrix6x12d::Zero();
  for (int a = 0; a < 4; ++a) {
    const auto& g = grad[a];
    const int c = 3 * a;
    B(0, c) = g.x();
    B(1, c + 1) = g.y();
    B(2, c + 2) = g.z();
    B(3, c + 1) = g.z();
    B(3, c + 2) = g.y();
    B(4, c) = g.z();
    B(4, c + 2) = g.x();
    B(5, c) = g.y();
    B(5, c + 1) = g.x();
  }
  return B;
}

Matrix12d element_stiffness(const TetCoords& x, const Matrix6d& D) {
  const Matrix6x12d B = strain_matrix(x);
  return std::abs(tet_volume(x)) * B.transpose() * D * B;
}

}  // namespace contact3d
