#include "linalg/schur_capture.hpp"

#include <dlfcn.h>

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <cholmod.h>

extern "C" {
void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const double* alpha, const double* a, const int* lda, double* b, const int* ldb);
void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha, const double* a,
            const int* lda, const double* beta, double* c, const int* ldc);
}

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

bool SchurCapture::works() {
  // [K b; bᵀ 0] with K = 2I (2 × 2), b = (1, 1): the Schur block is −bᵀK⁻¹b = −1.
  std::vector<SuiteSparse_long> col_ptr{0, 1, 2, 5}, row_idx{0, 1, 0, 1, 2};
  std::vector<double> values{2, 2, 1, 1, 0};
  cholmod_sparse A{};
  A.nrow = A.ncol = 3;
  A.nzmax = values.size();
  A.p = col_ptr.data();
  A.i = row_idx.data();
  A.x = values.data();
  A.stype = 1;
  A.itype = CHOLMOD_LONG;
  A.xtype = CHOLMOD_REAL;
  A.dtype = CHOLMOD_DOUBLE;
  A.sorted = A.packed = 1;
  cholmod_common c;
  cholmod_l_start(&c);
  c.print = 0;
  c.supernodal = CHOLMOD_SUPERNODAL;
  c.final_ll = 1;
  c.nmethods = 1;
  c.method[0].ordering = CHOLMOD_NATURAL;
  bool ok = false;
  {
    SchurCapture capture(1);
    cholmod_factor* L = cholmod_l_analyze(&A, &c);
    if (L) {
      cholmod_l_factorize(&A, L, &c);
      const std::size_t n = capture.fired() ? static_cast<std::size_t>(capture.block_size()) : 0;
      ok = n > 0 && c.status == CHOLMOD_OK && L->is_super && std::abs(capture.block()[n * n - 1] + 1.0) < 1e-12;
      cholmod_l_free_factor(&L, &c);
    }
  }
  cholmod_l_finish(&c);
  return ok;
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
