#include "linalg/symmetric_product.hpp"

#include <cmath>
#include <stdexcept>

#include "linalg/blas.hpp"

namespace contact3d {

Eigen::VectorXd symmetric_product(const DenseView& Q, const Eigen::VectorXd& v) {
  const int n = static_cast<int>(Q.rows()), lda = static_cast<int>(Q.outerStride()), one = 1;
  if (v.size() != n) throw std::invalid_argument("symmetric_product: vector size differs from Q");
  const double alpha = 1, beta = 0;
  Eigen::VectorXd out = Eigen::VectorXd::Zero(n);
  if (n > 0) dsymv_("L", &n, &alpha, Q.data(), &lda, v.data(), &one, &beta, out.data(), &one);
  return out;
}

Eigen::MatrixXd symmetric_block_product(const DenseView& Q, const Eigen::MatrixXd& V) {
  const int n = static_cast<int>(Q.rows()), lda = static_cast<int>(Q.outerStride()), k = static_cast<int>(V.cols());
  if (V.rows() != n) throw std::invalid_argument("symmetric_product: block rows differ from Q");
  const double alpha = 1, beta = 0;
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, k);
  if (n == 0 || k == 0) return out;
  if (k <= kColumnsByProducts) {
    const int one = 1;
    for (int j = 0; j < k; ++j)
      dsymv_("L", &n, &alpha, Q.data(), &lda, V.col(j).data(), &one, &beta, out.col(j).data(), &one);
    return out;
  }
  dsymm_("L", "L", &n, &k, &alpha, Q.data(), &lda, V.data(), &n, &beta, out.data(), &n);
  return out;
}

Eigen::VectorXd symmetric_product(const SingleSymmetric& Q_single, double scale, const Eigen::VectorXd& v) {
  const int n = Q_single.size, lda = Q_single.stride, one = 1;
  if (v.size() != n) throw std::invalid_argument("symmetric_product: vector size differs from Q");
  if (n == 0) return Eigen::VectorXd();
  const double v_scale = v.cwiseAbs().maxCoeff();
  if (v_scale == 0) return Eigen::VectorXd::Zero(n);
  if (!std::isfinite(v_scale)) return Eigen::VectorXd::Constant(n, v_scale);  // propagates NaN / inf
  const float alpha = 1, beta = 0;
  const Eigen::VectorXf x = (v / v_scale).cast<float>();
  Eigen::VectorXf out = Eigen::VectorXf::Zero(n);
  ssymv_(Q_single.upper ? "U" : "L", &n, &alpha, Q_single.data, &lda, x.data(), &one, &beta, out.data(), &one);
  return out.cast<double>() * (scale * v_scale);
}

Eigen::MatrixXf lower_triangle_in_single(const DenseView& Q, double scale, const Eigen::VectorXd& diagonal,
                                         bool spare_column) {
  const Eigen::Index m = Q.rows();
  Eigen::MatrixXf out(m, m + (spare_column ? 1 : 0));
  if (diagonal.size() == 0) {
    for (Eigen::Index j = 0; j < m; ++j) out.col(j).tail(m - j) = (Q.col(j).tail(m - j) / scale).cast<float>();
    return out;
  }
  if (diagonal.size() != m) throw std::invalid_argument("lower_triangle_in_single: diagonal size differs from Q");
  for (Eigen::Index j = 0; j < m; ++j)
    out.col(j).tail(m - j) =
        (Q.col(j).tail(m - j).cwiseProduct(diagonal.tail(m - j)) * (diagonal[j] / scale)).cast<float>();
  return out;
}

SingleSymmetric upper_triangle_in_single(const DenseView& Q, double scale, const Eigen::VectorXd& diagonal, float* out,
                                         int stride) {
  const Eigen::Index m = Q.rows();
  if (diagonal.size() != 0 && diagonal.size() != m)
    throw std::invalid_argument("upper_triangle_in_single: diagonal size differs from Q");
  for (Eigen::Index j = 0; j < m; ++j) {  // column j's rows 0..j: Q's own (both triangles are stored)
    Eigen::Map<Eigen::VectorXf> column(out + j * stride, j + 1);
    if (diagonal.size() == 0)
      column = (Q.col(j).head(j + 1) / scale).cast<float>();
    else
      column = (Q.col(j).head(j + 1).cwiseProduct(diagonal.head(j + 1)) * (diagonal[j] / scale)).cast<float>();
  }
  return SingleSymmetric(out, static_cast<int>(m), stride);
}

}  // namespace contact3d
