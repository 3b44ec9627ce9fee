// SchurCapture: the Schur complement of a supernodal Cholesky factorization, taken from inside it.
//
// Factoring the augmented matrix [K 𝔹ᵀ; 𝔹 0] with the multipliers ordered last, CHOLMOD assembles
// into its last (root) supernode the trailing block 0 − 𝔹K⁻¹𝔹ᵀ = −Q (every descendant's update
// lands there) and then calls LAPACK's dpotrf on it — which fails, −Q being negative definite. While
// a SchurCapture is alive, this process's dpotrf_ (it interposes LAPACK's: the executable's symbol
// comes first for CHOLMOD's shared library) factors only the leading columns of a root supernode that
// has at least `trailing` columns, updates the trailing block with them, and leaves that block as it
// is: −Q, exact to rounding, without factoring it (m³/3 flops) or forming Q again from the factor's
// off-diagonal rows (the trailing Gram, m²·width flops). Every other call goes to LAPACK unchanged.
//
// The interposer is process state by necessity (LAPACK has no hook); it is armed only inside a
// SchurCapture's lifetime, by one capture at a time, and records where it left the block so that
// the caller can check it is the factor's root supernode. Where the interposition does not take
// effect (a statically linked LAPACK), fired() stays false and the caller falls back.
#pragma once

namespace contact3d {

class SchurCapture {
 public:
  // Arms the interposer for a factorization whose last `trailing` pivots are the Schur block.
  explicit SchurCapture(int trailing);
  ~SchurCapture();
  SchurCapture(const SchurCapture&) = delete;
  SchurCapture& operator=(const SchurCapture&) = delete;

  // Whether a root supernode was factored partially, and where: its values (column-major, leading
  // dimension = its size) and its size; the Schur block is its trailing `trailing` × `trailing` part.
  bool fired() const { return block_ != nullptr; }
  const double* block() const { return block_; }
  int block_size() const { return block_size_; }

  // Called by the interposer: factor the leading columns of this root supernode (lda == n >= trailing,
  // lower triangle) and leave the Schur block unfactored. Returns LAPACK's info.
  int factor_leading(int n, double* a);
  int trailing() const { return trailing_; }

 private:
  int trailing_;
  double* block_ = nullptr;
  int block_size_ = 0;
};

}  // namespace contact3d
