#include "linalg/blas_buffers.hpp"

#include <dlfcn.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include <atomic>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "base/memory.hpp"
#include "linalg/blas.hpp"

namespace contact3d {
namespace {

constexpr std::uint64_t kBufferBytes = (128ull << 20) + 4096;  // one thread's buffer, as OpenBLAS maps it
constexpr std::uint64_t kMiB = 1ull << 20;
constexpr std::uint64_t kMargin = 16 * kMiB;  // beyond the buffers, for the solve's first steps

bool address_space_limited() {
  rlimit lim{};
  return getrlimit(RLIMIT_AS, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY;
}

// Whether `bytes` of address space can still be mapped (mapped and released at once, never touched).
bool can_map(std::uint64_t bytes) {
  void* p = mmap(nullptr, bytes, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (p == MAP_FAILED) return false;
  munmap(p, bytes);
  return true;
}

// A product large enough that OpenBLAS splits it over all its threads, each of which maps its buffer.
void run_on_every_thread() {
  const int n = 512;
  std::vector<double> a(static_cast<std::size_t>(n) * n, 1.0), c(static_cast<std::size_t>(n) * n, 0.0);
  const double one = 1.0, zero = 0.0;
  dgemm_("N", "N", &n, &n, &n, &one, a.data(), &n, a.data(), &n, &zero, c.data(), &n);
}

}  // namespace

BlasBuffers blas_buffers() {
  using ThreadCount = int (*)();
  const auto count = reinterpret_cast<ThreadCount>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  if (!count) return {};
  const int threads = count() > 0 ? count() : 1;
  // A buffer per thread, the caller being one of them.
  return {threads, static_cast<std::uint64_t>(threads) * kBufferBytes};
}

void reserve_blas_buffers() {
  // OpenBLAS's buffers are the process's, mapped once: so is this flag.
  static std::atomic<bool> reserved{false};
  if (reserved) return;
  const BlasBuffers buffers = blas_buffers();
  if (buffers.threads == 0 || !address_space_limited()) return;
  // Room for the buffers and a little besides, else OpenBLAS would hang in its first threaded call.
  if (!can_map(buffers.bytes + kMargin)) {
    const bool one_thread_fits = buffers.threads > 1 && can_map(kBufferBytes + kMargin);
    throw InputError("the address-space limit (ulimit -v) leaves " +
                     std::to_string(memory_detail::address_space_headroom() / kMiB) + " MiB, and OpenBLAS maps " +
                     std::to_string(kBufferBytes / kMiB) + " MiB of work space for each of its " +
                     std::to_string(buffers.threads) + " threads (" + std::to_string(buffers.bytes / kMiB) +
                     " MiB), waiting forever when it cannot: raise the limit" +
                     (one_thread_fits ? ", or set OPENBLAS_NUM_THREADS=1" : ""));
  }
  run_on_every_thread();
  reserved = true;
}

}  // namespace contact3d
