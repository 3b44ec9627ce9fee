#include "linalg/dense_cholesky.hpp"

#include <utility>

#include <Eigen/Cholesky>

extern "C" {
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info);
void dpotrs_(const char* uplo, const int* n, const int* nrhs, const double* a, const int* lda, double* b,
             const int* ldb, int* info);
}

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

}  // namespace contact3d
