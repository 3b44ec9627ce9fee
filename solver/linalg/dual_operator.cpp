#include "linalg/dual_operator.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

#include "linalg/blas.hpp"
#include "linalg/sparse_forward_solve.hpp"
#include "linalg/symmetric_product.hpp"

namespace contact3d {

int block_columns_for(Eigen::Index rows, int requested, long long block_bytes) {
  const long long n = std::max<long long>(1, rows);
  return static_cast<int>(std::clamp<long long>(block_bytes / (8 * n), 8, std::max(8, requested)));
}

DualOperator make_dual_operator(const SparseCholesky& K, const Eigen::SparseMatrix<double>& B, const Eigen::VectorXd& f,
                                int block_columns) {
  DualOperator op;
  const int m = static_cast<int>(B.rows());
  op.u_free = K.solve(f);
  op.h = B * op.u_free;
  op.solves = 1;
  op.Q.resize(m, m);
  const Eigen::SparseMatrix<double> Bt = B.transpose();
  block_columns = block_columns_for(B.cols(), block_columns);
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

Eigen::VectorXd forward_solved_diagonal(const SparseCholesky& K, const Eigen::SparseMatrix<double>& B,
                                        int block_columns) {
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(B.rows());
  // 16 MiB of workspace per block: this route is taken to save memory.
  forward_solve_sparse_columns(K, B.transpose(), block_columns, 16LL << 20,
                               [&](int j, std::span<const std::int64_t>, std::span<const double> values) {
                                 diagonal[j] =
                                     Eigen::Map<const Eigen::VectorXd>(values.data(), values.size()).squaredNorm();
                               });
  return diagonal;
}

std::vector<int> contact_dofs(const Eigen::SparseMatrix<double>& B) {
  std::vector<char> used(B.cols(), 0);
  for (int k = 0; k < B.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(B, k); it; ++it)
      if (it.value() != 0) used[it.col()] = 1;
  std::vector<int> dofs;
  for (int j = 0; j < B.cols(); ++j)
    if (used[j]) dofs.push_back(j);
  return dofs;
}

DualOperator make_dual_operator_schur(const SparseCholesky& K, const Eigen::SparseMatrix<double>& B,
                                      const Eigen::VectorXd& f) {
  DualOperator op;
  const int m = static_cast<int>(B.rows());
  op.u_free = K.solve(f);
  op.h = B * op.u_free;
  op.solves = 1;
  std::vector<int> order;
  const Eigen::MatrixXd Ltt = K.trailing_factor(order);
  const int nt = static_cast<int>(order.size());
  // X = 𝔹_tᵀ in the factor's order; every nonzero of 𝔹 must sit in a trailing column.
  std::vector<int> pos(B.cols(), -1);
  for (int k = 0; k < nt; ++k) pos[order[k]] = k;
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(nt, m);
  for (int k = 0; k < B.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(B, k); it; ++it) {
      if (it.value() == 0) continue;
      const int p = pos[it.col()];
      if (p < 0) throw std::logic_error("make_dual_operator_schur: 𝔹 touches a dof outside the trailing block");
      X(p, it.row()) = it.value();
    }
  op.Q.resize(m, m);
  if (nt == 0 || m == 0) {
    op.Q.setZero();
    return op;
  }
  const double one = 1, zero = 0;
  dtrsm_("L", "L", "N", "N", &nt, &m, &one, Ltt.data(), &nt, X.data(), &nt);
  dsyrk_("U", "T", &m, &nt, &one, X.data(), &nt, &zero, op.Q.data(), &m);
  for (int j = 0; j < m; ++j)
    for (int i = j + 1; i < m; ++i) op.Q(i, j) = op.Q(j, i);
  return op;
}

DualOperator make_dual_operator_augmented(SparseCholesky& K_aug, const Eigen::SparseMatrix<double>& B,
                                          const Eigen::VectorXd& f, const Eigen::VectorXd* u_free) {
  if (!K_aug.augmented() || K_aug.trailing_size() != B.rows())
    throw std::logic_error("make_dual_operator_augmented: not the augmented factor of this 𝔹");
  DualOperator op;
  op.u_free = u_free ? *u_free : K_aug.solve(f);
  op.h = B * op.u_free;
  op.solves = u_free ? 0 : 1;
  const std::vector<int> order = K_aug.trailing_order();  // n + (row of 𝔹), in the factor's order
  const int m = static_cast<int>(B.rows()), n = K_aug.size();
  std::vector<int> row(m);
  for (int k = 0; k < m; ++k) row[k] = order[k] - n;
  bool in_order = true;  // the usual case: the factor keeps 𝔹's rows in the order they were given
  for (int k = 0; k < m && in_order; ++k) in_order = row[k] == k;
  // G (trailing order) into 𝔹's order; G is symmetric to the bit (both triangles mirrored): only permute.
  const auto permuted = [&row, m](const DenseView& G) {
    Eigen::MatrixXd Q(m, m);
    for (int b = 0; b < m; ++b) {
      double* column = Q.col(row[b]).data();
      for (int a = 0; a < m; ++a) column[row[a]] = G(a, b);
    }
    return Q;
  };
  if (K_aug.captured_schur()) {
    if (in_order)
      op.Q_in_factor = DenseViewPtr(K_aug.schur_block());
    else
      op.Q = permuted(K_aug.schur_block());
    return op;
  }
  Eigen::MatrixXd G = K_aug.trailing_gram();
  op.Q = in_order ? std::move(G) : permuted(G);
  return op;
}

namespace {

using Product = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

// The norm estimate's stopping test is read from this many products on (dual operators: the test
// holds after 4 to 6, each a read of Q; a few more make a missed top eigenvalue less likely).
constexpr int kMinNormSteps = 10;

// Up to `steps` Lanczos steps (fully reorthogonalised) from a fixed pseudo-random start, and the
// extreme Ritz values. With `top_tolerance` > 0 it stops (after kMinNormSteps) once the largest Ritz pair (θ, y) has
// the residual ‖Q y − θ y‖ = β_k |s_k| <= top_tolerance · θ: an eigenvalue then lies within that of θ (the
// tridiagonal's eigenvectors, k × k, cost nothing beside a product).
SpectrumEstimate lanczos(Eigen::Index size, const Product& product, int steps, double top_tolerance) {
  SpectrumEstimate out;
  if (size == 0 || steps <= 0) return out;
  steps = static_cast<int>(std::min<Eigen::Index>(steps, size));
  std::mt19937_64 random(2009);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::MatrixXd V(size, steps);  // the Lanczos basis
  V.col(0) = Eigen::VectorXd::NullaryExpr(size, [&] { return uniform(random); }).normalized();
  Eigen::VectorXd alpha(steps), beta = Eigen::VectorXd::Zero(steps);
  const auto tridiagonal = [&](int n) {
    Eigen::MatrixXd T = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) {
      T(i, i) = alpha[i];
      if (i + 1 < n) T(i, i + 1) = T(i + 1, i) = beta[i];
    }
    return T;
  };
  int k = 0;
  for (; k < steps; ++k) {
    Eigen::VectorXd w = product(V.col(k));
    ++out.products;
    alpha[k] = V.col(k).dot(w);
    for (int pass = 0; pass < 2; ++pass)  // full reorthogonalisation, twice is enough
      w -= V.leftCols(k + 1) * (V.leftCols(k + 1).transpose() * w);
    if (k + 1 == steps) break;
    beta[k] = w.norm();
    if (!(beta[k] > 1e-14 * std::abs(alpha[k]))) break;  // an invariant subspace (or NaN): the Ritz values are exact
    if (top_tolerance > 0 && k + 1 >= kMinNormSteps) {
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> ritz(tridiagonal(k + 1));
      const Eigen::Index top = k;  // eigenvalues ascending
      if (ritz.info() == Eigen::Success &&
          beta[k] * std::abs(ritz.eigenvectors()(k, top)) <= top_tolerance * ritz.eigenvalues()[top])
        break;
    }
    V.col(k + 1) = w / beta[k];
  }
  const int n = k + 1;  // the steps taken (the loop leaves by a break, k < steps)
  if (!alpha.head(n).allFinite() || !beta.head(n).allFinite()) {
    out.largest = out.smallest = std::numeric_limits<double>::quiet_NaN();
    return out;
  }
  const Eigen::VectorXd ritz =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(tridiagonal(n), Eigen::EigenvaluesOnly).eigenvalues();
  out.smallest = ritz.minCoeff();
  out.largest = ritz.maxCoeff();
  return out;
}

// ‖Q‖ to this share: callers add a 5% margin.
constexpr double kNormTolerance = 1e-3;

double largest_eigenvalue(Eigen::Index size, const Product& product, int steps) {
  return lanczos(size, product, steps, kNormTolerance).largest;
}

}  // namespace

double estimate_norm(Eigen::Index size, const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& product,
                     int iterations) {
  return largest_eigenvalue(size, product, iterations);
}

SpectrumEstimate lanczos_extremes(Eigen::Index size,
                                  const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& product, int steps) {
  return lanczos(size, product, steps, 0.0);
}

double estimate_norm(const DenseView& Q, int iterations) {
  return largest_eigenvalue(
      Q.rows(), [&](const Eigen::VectorXd& x) { return symmetric_product(Q, x); }, iterations);
}

double estimate_norm(const SingleSymmetric& Q_single, double scale, int iterations) {
  return largest_eigenvalue(
      Q_single.size, [&](const Eigen::VectorXd& x) { return symmetric_product(Q_single, scale, x); }, iterations);
}

}  // namespace contact3d
