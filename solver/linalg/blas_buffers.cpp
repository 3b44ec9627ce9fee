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
  const std::uint64_t limit = memory_detail::address_space_limit();  // 0: none
  if (threads == 0 || limit == 0) return;
  const std::uint64_t bytes = static_cast<std::uint64_t>(threads) * kBufferBytes;
  // Room for the buffers and a little besides, else OpenBLAS would hang in its first threaded call.
  if (!can_map(bytes + kMargin)) {
    const bool one_thread_fits = threads > 1 && can_map(kBufferBytes + kMargin);
    // The limit itself, not what it leaves: an OpenBLAS worker started with the library and retrying to
    // map its work space makes the process's mapped size jump (31, 16, 105, 1 MiB left at 100 … 200 MB).
    throw InputError(
        "the address-space limit (ulimit -v) of " + std::to_string(limit / kMiB) + " MiB is too low: OpenBLAS maps " +
        std::to_string(kBufferBytes / kMiB) + " MiB of work space " +
        (threads == 1
             ? std::string("for its one thread")
             : "for each of its " + std::to_string(threads) + " threads (" + std::to_string(bytes / kMiB) + " MiB)") +
        " beyond the " + std::to_string(kMargin / kMiB) + " MiB the solve's first steps need and the libraries and " +
        "data the process maps already, waiting forever when it cannot: raise the limit" +
        (one_thread_fits ? ", or set OPENBLAS_NUM_THREADS=1" : ""));
  }
  run_on_every_thread();
  reserved = true;
}

}  // namespace contact3d
