#include "linalg/schur_capture.hpp"

#include <dlfcn.h>

#include <atomic>
#include <stdexcept>

#include "linalg/blas.hpp"

namespace contact3d {
namespace {

using Potrf = void (*)(const char*, const int*, double*, const int*, int*);

std::atomic<SchurCapture*> armed{nullptr};  // the capture alive, if any (see the header)

// LAPACK's own dpotrf_: the next definition after this executable's (null if there is none).
Potrf lapack_potrf() {
  static const Potrf real = reinterpret_cast<Potrf>(dlsym(RTLD_NEXT, "dpotrf_"));
  return real;
}

}  // namespace

SchurCapture::SchurCapture(int trailing) : trailing_(trailing) {
  SchurCapture* expected = nullptr;
  if (!armed.compare_exchange_strong(expected, this)) throw std::logic_error("SchurCapture: one at a time");
}

SchurCapture::~SchurCapture() { armed.store(nullptr); }

int SchurCapture::factor_leading(int n, double* a) {
  const int k = n - trailing_, m = trailing_;
  int info = 0;
  if (k > 0) {
    const Potrf potrf = lapack_potrf();
    if (!potrf) return -1;
    potrf("L", &k, a, &n, &info);
    if (info != 0) return info;
    const double one = 1, minus_one = -1;
    dtrsm_("R", "L", "T", "N", &m, &k, &one, a, &n, a + k, &n);                             // A21 ← A21 L11⁻ᵀ
    dsyrk_("L", "N", &m, &k, &minus_one, a + k, &n, &one, a + k + std::size_t(k) * n, &n);  // A22 −= A21 A21ᵀ
  }
  block_ = a;
  block_size_ = n;
  return 0;
}

}  // namespace contact3d

// LAPACK's dpotrf_, interposed (see schur_capture.hpp): a root supernode of the armed capture's
// factorization is factored partially, every other call goes to LAPACK.
extern "C" void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info) {
  contact3d::SchurCapture* capture = contact3d::armed.load();
  if (capture && (*uplo == 'L' || *uplo == 'l') && *n == *lda && *n >= capture->trailing() && !capture->fired()) {
    *info = capture->factor_leading(*n, a);
    return;
  }
  if (const contact3d::Potrf potrf = contact3d::lapack_potrf()) {
    potrf(uplo, n, a, lda, info);
  } else {
    *info = -1;  // no LAPACK behind us: the caller reports a failed factorization
  }
}
