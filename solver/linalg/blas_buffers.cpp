#include "linalg/blas_buffers.hpp"

#include <sys/mman.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "base/memory.hpp"
#include "linalg/blas.hpp"
#include "linalg/blas_threads.hpp"

namespace contact3d {
namespace {

constexpr std::uint64_t kBufferBytes = (128ull << 20) + 4096;  // one thread's buffer, as OpenBLAS maps it
constexpr std::uint64_t kMiB = 1ull << 20;
constexpr std::uint64_t kMargin = 16 * kMiB;  // beyond the buffers, for the solve's first steps

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

void reserve_blas_buffers() {
  // OpenBLAS's buffers are the process's, mapped once: so is this flag.
  static std::atomic<bool> reserved{false};
  if (reserved) return;
  // Each OpenBLAS thread, the caller one of them, maps a buffer (0 threads: the BLAS is not OpenBLAS).
  const int threads = current_blas_threads().threads;
  const std::uint64_t headroom = memory_detail::address_space_headroom();  // 0: no limit
  if (threads == 0 || headroom == 0) return;
  const std::uint64_t bytes = static_cast<std::uint64_t>(threads) * kBufferBytes;
  // Room for the buffers and a little besides, else OpenBLAS would hang in its first threaded call.
  if (!can_map(bytes + kMargin)) {
    const bool one_thread_fits = threads > 1 && can_map(kBufferBytes + kMargin);
    throw InputError("the address-space limit (ulimit -v) leaves " + std::to_string(headroom / kMiB) +
                     " MiB, and OpenBLAS maps " + std::to_string(kBufferBytes / kMiB) + " MiB of work space " +
                     (threads == 1 ? std::string("for its one thread")
                                   : "for each of its " + std::to_string(threads) + " threads (" +
                                         std::to_string(bytes / kMiB) + " MiB)") +
                     ", waiting forever when it cannot: raise the limit" +
                     (one_thread_fits ? ", or set OPENBLAS_NUM_THREADS=1" : ""));
  }
  run_on_every_thread();
  reserved = true;
}

}  // namespace contact3d
