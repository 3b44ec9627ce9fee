// DenseView: a read-only view of a dense column-major matrix whose storage is held elsewhere — an
// Eigen matrix, or the trailing block of the augmented factor, where the factorization leaves
// Q = 𝔹K⁻¹𝔹ᵀ (sparse_cholesky.hpp) and where it stays instead of being copied out (777 MiB at 10 092
// multipliers). Columns are contiguous and outerStride() apart; a function taking a DenseView takes
// an Eigen::MatrixXd as well, without copying it.
//
// DenseViewPtr: a nullable handle to such a view, used like a `const Eigen::MatrixXd*` (null: none).
#pragma once

#include <algorithm>
#include <cstddef>

#include <Eigen/Core>

namespace contact3d {

using DenseView = Eigen::Ref<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;

// The rows × cols matrix at `data` whose columns are `stride` apart (stride >= rows).
inline DenseView strided_view(const double* data, Eigen::Index rows, Eigen::Index cols, Eigen::Index stride) {
  using StridedMap = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
  return DenseView(StridedMap(data, rows, cols, Eigen::OuterStride<>(stride)));
}

class DenseViewPtr {
 public:
  DenseViewPtr() = default;
  DenseViewPtr(std::nullptr_t) {}              // NOLINT: pointer-like
  DenseViewPtr(const Eigen::MatrixXd* matrix)  // NOLINT: pointer-like
      : data_(matrix ? matrix->data() : nullptr),
        rows_(matrix ? matrix->rows() : 0),
        cols_(matrix ? matrix->cols() : 0),
        stride_(std::max<Eigen::Index>(1, rows_)),
        set_(matrix != nullptr) {}
  explicit DenseViewPtr(const DenseView& view)
      : data_(view.data()), rows_(view.rows()), cols_(view.cols()), stride_(view.outerStride()), set_(true) {}

  explicit operator bool() const { return set_; }
  bool operator==(std::nullptr_t) const { return !set_; }
  DenseView operator*() const { return strided_view(data_, rows_, cols_, stride_); }

 private:
  const double* data_ = nullptr;
  Eigen::Index rows_ = 0, cols_ = 0, stride_ = 1;
  bool set_ = false;
};

}  // namespace contact3d
