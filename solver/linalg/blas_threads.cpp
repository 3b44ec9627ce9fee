#include "linalg/blas_threads.hpp"

#include <dlfcn.h>

namespace contact3d {
namespace {

using SetFn = void (*)(int);
using GetFn = int (*)();

SetFn set_fn() {
  static const SetFn f = reinterpret_cast<SetFn>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  return f;
}
GetFn get_fn() {
  static const GetFn f = reinterpret_cast<GetFn>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  return f;
}

}  // namespace

ScopedBlasThreads::ScopedBlasThreads(int threads) {
  if (set_fn() && get_fn()) {
    previous_ = get_fn()();
    if (previous_ != threads) set_fn()(threads);
    else previous_ = 0;
  }
}

ScopedBlasThreads::~ScopedBlasThreads() {
  if (previous_ > 0 && set_fn()) set_fn()(previous_);
}

}  // namespace contact3d
