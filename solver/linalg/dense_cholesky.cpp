#include "linalg/dense_cholesky.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "linalg/blas.hpp"

namespace contact3d {
namespace {
// Below this size Eigen's unblocked LLT beats LAPACK (measured: at n = 144 waking two OpenBLAS
// threads on a busy machine cost 20x the factorization).
constexpr Eigen::Index kLapackMin = 400;
}  // namespace

DenseCholesky::DenseCholesky(Eigen::MatrixXd A) : L_(std::move(A)) {
  const int n = static_cast<int>(L_.rows());
  if (n == 0) {
    ok_ = true;
    return;
  }
  if (n < kLapackMin) {
    Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(L_);  // in place, lower triangle
    ok_ = llt.info() == Eigen::Success;
  } else {
    int info = 0;
    dpotrf_("L", &n, L_.data(), &n, &info);
    ok_ = info == 0;
  }
  ok_ = ok_ && L_.diagonal().allFinite();
}

Eigen::VectorXd DenseCholesky::solve(const Eigen::VectorXd& b) const {
  Eigen::VectorXd x = b;
  const int n = static_cast<int>(L_.rows());
  if (n == 0) return x;
  if (n < kLapackMin) {
    const auto L = L_.triangularView<Eigen::Lower>();
    L.solveInPlace(x);
    L.transpose().solveInPlace(x);
  } else {
    int info = 0, one = 1;
    dpotrs_("L", &n, &one, L_.data(), &n, x.data(), &n, &info);
  }
  return x;
}

Eigen::MatrixXd DenseCholesky::solve_columns(const Eigen::MatrixXd& B) const {
  Eigen::MatrixXd X = B;
  const int n = static_cast<int>(L_.rows()), k = static_cast<int>(B.cols());
  if (n == 0 || k == 0) return X;
  if (n < kLapackMin) {
    const auto L = L_.triangularView<Eigen::Lower>();
    L.solveInPlace(X);
    L.transpose().solveInPlace(X);
  } else {
    int info = 0;
    dpotrs_("L", &n, &k, L_.data(), &n, X.data(), &n, &info);
  }
  return X;
}

SingleCholesky::SingleCholesky(Eigen::MatrixXf A) : L_(std::move(A)) {
  const int n = static_cast<int>(L_.rows());
  int info = 0;
  if (n > 0) spotrf_("L", &n, L_.data(), &n, &info);
  ok_ = info == 0 && L_.diagonal().allFinite();
}

Eigen::VectorXd SingleCholesky::solve(const Eigen::VectorXd& b) const {
  const int n = static_cast<int>(L_.rows()), one = 1;
  if (n == 0) return b;
  const double scale = b.cwiseAbs().maxCoeff();
  if (!(scale > 0) || !std::isfinite(scale)) return Eigen::VectorXd::Zero(n) * scale;
  Eigen::VectorXf x = (b / scale).cast<float>();
  int info = 0;
  spotrs_("L", &n, &one, L_.data(), &n, x.data(), &n, &info);
  return x.cast<double>() * scale;
}

Eigen::MatrixXd SingleCholesky::solve_columns(const Eigen::MatrixXd& B) const {
  const int n = static_cast<int>(L_.rows()), k = static_cast<int>(B.cols());
  if (n == 0 || k == 0) return B;
  const double scale = B.cwiseAbs().maxCoeff();
  if (!(scale > 0) || !std::isfinite(scale)) return Eigen::MatrixXd::Zero(n, k) * scale;
  Eigen::MatrixXf X = (B / scale).cast<float>();
  int info = 0;
  spotrs_("L", &n, &k, L_.data(), &n, X.data(), &n, &info);
  return X.cast<double>() * scale;
}

namespace {

// Subspace iteration on A⁻¹ (through `factor`), then Rayleigh–Ritz with A.
template <class Factor>
double smallest_eigenvalue_with(const Factor& factor, const DenseView& A, const Eigen::VectorXd& scale) {
  const Eigen::Index n = A.rows(), k = std::min<Eigen::Index>(8, n);
  constexpr int kIterations = 12;
  const bool scaled = scale.size() == n;
  std::mt19937 gen(1);  // fixed: the same estimate on every run
  std::normal_distribution<double> normal;
  Eigen::MatrixXd X(n, k);
  for (Eigen::Index i = 0; i < X.size(); ++i) X.data()[i] = normal(gen);
  for (int it = 0; it < kIterations; ++it) {
    if (scaled) X = scale.cwiseInverse().asDiagonal() * X;
    Eigen::MatrixXd Y = factor.solve_columns(X);
    if (scaled) Y = scale.cwiseInverse().asDiagonal() * Y;
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(Y);
    X = qr.householderQ() * Eigen::MatrixXd::Identity(n, k);
  }
  const Eigen::MatrixXd SX = scaled ? Eigen::MatrixXd(scale.asDiagonal() * X) : X;
  const Eigen::MatrixXd AX = A.selfadjointView<Eigen::Lower>() * SX;
  const Eigen::MatrixXd T = SX.transpose() * AX;
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(T, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
}

}  // namespace

double smallest_eigenvalue(const DenseCholesky& factor, const DenseView& A, const Eigen::VectorXd& scale) {
  return smallest_eigenvalue_with(factor, A, scale);
}

double smallest_eigenvalue(const SingleCholesky& factor, const DenseView& A, const Eigen::VectorXd& scale) {
  return smallest_eigenvalue_with(factor, A, scale);
}

}  // namespace contact3d
