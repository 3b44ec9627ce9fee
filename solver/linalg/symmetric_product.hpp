// Products with a dense symmetric matrix of which only the lower triangle is read (the dual
// operator Q and its copies): BLAS dsymv / ssymv, on the BLAS threads. Reading one triangle halves
// the memory traffic that bounds a product once Q outgrows the caches; single precision halves it
// again (ssymv 1.8-2.7x faster than dsymv at 4800-14000 rows on the 2-core machine).
#pragma once

#include <algorithm>

#include <Eigen/Core>

#include "linalg/dense_view.hpp"

namespace contact3d {

// Q v.
Eigen::VectorXd symmetric_product(const DenseView& Q, const Eigen::VectorXd& v);
// Q V for several columns at once (BLAS dsymm: Q is read once for all of them, where a product per
// column reads it per column). Up to kColumnsByProducts columns, one dsymv each instead: dsymm first
// copies the triangle it reads into a full panel, which costs more than a few passes over it (Q of
// 4 464 rows, one thread: 7 columns 30 ms by dsymm, 20 ms by 7 dsymv; 1 column 18 against 3.2 ms;
// 13 columns 31 against 42 ms) — a body held by contact alone refines its six motions' Jacobian (7
// columns) a few hundred times.
inline constexpr int kColumnsByProducts = 8;
Eigen::MatrixXd symmetric_block_product(const DenseView& Q, const Eigen::MatrixXd& V);

// A symmetric size × size matrix in single precision of which one triangle is stored (column-major,
// columns `stride` apart): the lower one (lower_triangle_in_single's copy), or the upper one, kept
// above a Cholesky factor in the same array (upper_triangle_in_single, SingleCholesky::spare_upper).
// Used like a pointer to the copy; null (the default): none.
struct SingleSymmetric {
  const float* data = nullptr;
  int size = 0, stride = 1;
  bool upper = false;
  SingleSymmetric() = default;
  SingleSymmetric(const Eigen::MatrixXf* lower)  // NOLINT: pointer-like; its lower triangle
      : data(lower ? lower->data() : nullptr),
        size(lower ? static_cast<int>(lower->rows()) : 0),
        stride(lower ? std::max(1, static_cast<int>(lower->rows())) : 1) {}
  SingleSymmetric(const float* upper_data, int n, int columns_apart)
      : data(upper_data), size(n), stride(columns_apart), upper(true) {}
  explicit operator bool() const { return data != nullptr; }
};

// scale · Q_single · v, computed in single precision with v scaled to unit max-norm (no under- or
// overflow for any v); rounding error about 1e-7 ‖Q‖‖v‖.
Eigen::VectorXd symmetric_product(const SingleSymmetric& Q_single, double scale, const Eigen::VectorXd& v);

// The lower triangle of Q / scale in single precision (the upper one is left unset: never read); with
// `diagonal` (size of Q), of S Q S / scale, S = diag(diagonal). With `spare_column`, in an array of
// one column more, whose upper part a second matrix may take once the lower one is factored in place
// (SingleCholesky::spare_upper).
Eigen::MatrixXf lower_triangle_in_single(const DenseView& Q, double scale,
                                         const Eigen::VectorXd& diagonal = Eigen::VectorXd(),
                                         bool spare_column = false);

// The same written as an upper triangle at `out` (columns `stride` apart), returned as that view.
SingleSymmetric upper_triangle_in_single(const DenseView& Q, double scale, const Eigen::VectorXd& diagonal, float* out,
                                         int stride);

}  // namespace contact3d
