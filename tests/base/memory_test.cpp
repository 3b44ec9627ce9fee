// base/memory.hpp: the allocator policy (freed large blocks are reused without new page faults,
// and handed back on request) and the available-memory estimate.
#include "base/memory.hpp"

#include <sys/resource.h>

#include <cstdlib>
#include <cstring>

#include <gtest/gtest.h>

namespace contact3d {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitizedAllocator = true;  // ASan has its own allocator: mallopt does nothing
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitizedAllocator = true;
#else
constexpr bool kSanitizedAllocator = false;
#endif
#else
constexpr bool kSanitizedAllocator = false;
#endif

long minor_faults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

// Page faults while allocating, touching and freeing `bytes`.
long faults_to_touch(std::size_t bytes) {
  const long before = minor_faults();
  auto* block = static_cast<char*>(std::malloc(bytes));
  EXPECT_NE(block, nullptr);
  std::memset(block, 1, bytes);
  asm volatile("" : : "r"(block) : "memory");  // the compiler may not drop the unused block
  std::free(block);
  return minor_faults() - before;
}

TEST(Memory, FreedLargeBlocksAreReusedWithoutNewPageFaults) {
  if (kSanitizedAllocator) GTEST_SKIP() << "the sanitizer's allocator ignores mallopt";
  keep_freed_memory();
  constexpr std::size_t kBytes = std::size_t(64) << 20;  // 16384 pages
  faults_to_touch(kBytes);                               // first touch: the heap grows
  EXPECT_LT(faults_to_touch(kBytes), 200);               // reused: (almost) no new pages
  release_freed_memory();                                // handed back: touching faults again
  EXPECT_GT(faults_to_touch(kBytes), 8000);
}

TEST(Memory, AvailableMemoryCountsTheHeapKeptFree) {
  if (kSanitizedAllocator) GTEST_SKIP() << "the sanitizer's allocator ignores mallopt";
  keep_freed_memory();
  release_freed_memory();
  const std::uint64_t free_before = memory_detail::allocator_free_bytes();
  faults_to_touch(std::size_t(64) << 20);
  EXPECT_GE(memory_detail::allocator_free_bytes(), free_before + (std::uint64_t(60) << 20));
  EXPECT_GT(available_memory_bytes(), std::uint64_t(60) << 20);
  release_freed_memory();
}

}  // namespace
}  // namespace contact3d
