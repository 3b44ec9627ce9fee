// SinglePrecisionFactor: a single-precision copy of a supernodal Cholesky factor P K Pᵀ = L Lᵀ
// (sparse_cholesky.hpp) and its own supernodal solves K⁻¹b = Pᵀ L⁻ᵀ L⁻¹ P b in float (BLAS
// strsv/sgemv per supernode; strsm/sgemm for several right-hand sides). A solve by a factor of
// hundreds of millions of entries reads the whole factor twice and is bound by memory bandwidth:
// the float copy halves the bytes. Its result carries the rounding of a perturbed K (a relative
// error of order 1e-7 · cond(K) at worst), so it serves only products whose errors the caller
// checks in double (mpgp.hpp's recursive gradient updates).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "linalg/sparse_cholesky.hpp"

namespace contact3d {

class SinglePrecisionFactor {
 public:
  // Copies the values of `factor` (a factor of K alone, not augmented), which must outlive this
  // object: its structure (supernodes, rows, permutation) is read in place.
  explicit SinglePrecisionFactor(const SparseCholesky& factor);

  // K⁻¹ b; b is scaled to unit max-norm in float (no under- or overflow) and the result back.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // K⁻¹ B, column by column scaled as solve(); BLAS-3 per supernode.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B) const;

  int size() const { return static_cast<int>(L_.n); }
  // The copy's size: 4 bytes per entry of L.
  static double bytes_for(const SparseCholesky& factor);

 private:
  // Supernode s of the float copy: its columns first_column .. first_column + columns − 1, a
  // column-major block of `rows` rows (its own columns' first), and the row indices below them.
  struct Supernode {
    std::int64_t first_column = 0;
    int columns = 0, rows = 0;
    const float* values = nullptr;
    const std::int64_t* rows_below = nullptr;
  };

  SparseCholesky::Supernodes L_;
  std::vector<float> values_;  // L's values in float, laid out as L_.values

  Supernode supernode(std::int64_t s) const;
  // X (n × k, column-major, pivot order) ← L⁻ᵀ L⁻¹ X in place, supernode by supernode: forward
  // ascending, backward descending; `below` is workspace for the rows below a supernode.
  void solve_in_pivot_order(float* X, int k) const;
  void forward_step(const Supernode& s, float* X, int k, std::vector<float>& below) const;
  void backward_step(const Supernode& s, float* X, int k, std::vector<float>& below) const;
};

}  // namespace contact3d
