// BLAS thread count, scoped. Multithreaded OpenBLAS pays for waking its threads on every call;
// on the small dense kernels of one triangular solve (supernodes of a single right-hand side)
// or a few-hundred-square LU that costs more than the work, and on a busy machine much more.
// ScopedBlasThreads(1) around such phases; a no-op when the BLAS is not OpenBLAS (looked up
// at run time, so any BLAS still links).
#pragma once

namespace contact3d {

class ScopedBlasThreads {
 public:
  explicit ScopedBlasThreads(int threads);
  ~ScopedBlasThreads();
  ScopedBlasThreads(const ScopedBlasThreads&) = delete;
  ScopedBlasThreads& operator=(const ScopedBlasThreads&) = delete;

 private:
  int previous_ = 0;
};

}  // namespace contact3d
