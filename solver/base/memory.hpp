// What this process can still get: MemAvailable from /proc/meminfo plus what its allocator holds
// free, capped by the cgroup's memory limit (containers, batch schedulers) and by the
// address-space limit (ulimit -v) minus what the process already maps; 0 when unknown. Size limits
// follow the machine instead of a fixed number.
//
// And how the process allocates: a solve allocates and frees dense m × m arrays (Q, its copies, the
// Newton matrices) and sparse factors stage after stage. glibc serves each such block with a fresh
// mmap and unmaps it on free, so every stage touches new pages and pays a page fault per 4 KiB (11 µs
// each on the 2-core virtual machine we measure on). keep_freed_memory() makes large
// blocks come from the heap and stay there when freed, so a later stage reuses pages already
// touched: on the slab at h = 0.025 page faults 519k → 263k (the peak working set), wall time
// 13.3 → 9.4 s, peak resident memory 1036 → 1058 MiB. release_freed_memory() hands the free heap
// back (before timing a reference factorization that must start as cold as the first).
// restart_with_huge_pages() has those pages come 2 MiB at a time (below).
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string>

#include <sys/resource.h>
#include <unistd.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

namespace contact3d {

namespace memory_detail {

inline std::uint64_t meminfo_available() {
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  std::uint64_t kib = 0;
  while (in >> key >> kib >> unit)
    if (key == "MemAvailable:") return kib * 1024;
  return 0;
}

// cgroup v2: memory.max − memory.current of this process's group ("max": no limit).
inline std::uint64_t cgroup_headroom() {
  std::ifstream max_in("/sys/fs/cgroup/memory.max"), cur_in("/sys/fs/cgroup/memory.current");
  std::string max_text;
  std::uint64_t current = 0;
  if (!(max_in >> max_text) || max_text == "max" || !(cur_in >> current)) return 0;
  const std::uint64_t limit = std::stoull(max_text);
  return limit > current ? limit - current : 1;
}

// RLIMIT_AS minus the process's current virtual size (/proc/self/statm, pages).
// The address-space limit (ulimit -v) in bytes; 0 where there is none.
inline std::uint64_t address_space_limit() {
  rlimit lim{};
  if (getrlimit(RLIMIT_AS, &lim) != 0 || lim.rlim_cur == RLIM_INFINITY) return 0;
  return lim.rlim_cur;
}

inline std::uint64_t address_space_headroom() {
  const std::uint64_t limit = address_space_limit();
  if (limit == 0) return 0;
  std::ifstream statm("/proc/self/statm");
  std::uint64_t pages = 0;
  statm >> pages;
  const std::uint64_t used = pages * 4096;
  return limit > used ? limit - used : 1;
}

// Bytes the allocator holds free (reusable without asking the system).
inline std::uint64_t allocator_free_bytes() {
#ifdef __GLIBC__
  return static_cast<std::uint64_t>(mallinfo2().fordblks);
#else
  return 0;
#endif
}

}  // namespace memory_detail

inline void keep_freed_memory() {
#ifdef __GLIBC__
  mallopt(M_MMAP_MAX, 0);                                      // large blocks from the heap, not from mmap
  mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());  // freed heap stays with the process
#endif
}

inline void release_freed_memory() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

// For the scope of one allocation-heavy call into a library that keeps its own large workspaces
// (MUMPS's factorization): blocks of 256 KiB and more come from the system and go back to it when
// freed, so that the heap's free holes, resident under keep_freed_memory(), are not left beside a
// workspace too large to fit in them. The policy of keep_freed_memory() comes back at the end.
class LargeBlocksFromSystem {
 public:
  LargeBlocksFromSystem() {
#ifdef __GLIBC__
    malloc_trim(0);
    mallopt(M_MMAP_MAX, 65536);             // glibc's default
    mallopt(M_MMAP_THRESHOLD, 256 * 1024);  // fixed: no dynamic raising after a large free
#endif
  }
  ~LargeBlocksFromSystem() { keep_freed_memory(); }
  LargeBlocksFromSystem(const LargeBlocksFromSystem&) = delete;
  LargeBlocksFromSystem& operator=(const LargeBlocksFromSystem&) = delete;
};

// The first touch of each page is a fault, 11 µs per 4 KiB page on the virtual machine we measure on:
// 2.8 s per GiB of factor or dense Q, where the same memory in transparent huge pages (2 MiB) costs
// about 0.15 s. The kernel gives them only to memory its owner asks for (madvise, the usual policy,
// /sys/kernel/mm/transparent_hugepage/enabled), and glibc asks for its heap and large blocks only with
// the tunable glibc.malloc.hugetlb=1, which it reads from GLIBC_TUNABLES when the process starts. So
// the program starts once more, the same process (exec keeps its id, arguments and open files), with
// the tunable added: where GLIBC_TUNABLES already names glibc.malloc.hugetlb (the restarted process, or
// a user's own choice, =0 for 4 KiB pages) it returns at once, and where exec fails it goes on as it
// was. Programs started by this one (gmsh, FreeFEM) inherit the variable.
inline void restart_with_huge_pages(char** argv) {
#ifdef __GLIBC__
  constexpr const char* kTunable = "glibc.malloc.hugetlb";
  const char* set = std::getenv("GLIBC_TUNABLES");
  const std::string before = set ? set : "";
  if (before.find(kTunable) != std::string::npos) return;
  const std::string with = (before.empty() ? "" : before + ":") + kTunable + "=1";
  if (setenv("GLIBC_TUNABLES", with.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  if (set)  // exec failed: as before
    setenv("GLIBC_TUNABLES", before.c_str(), 1);
  else
    unsetenv("GLIBC_TUNABLES");
#else
  (void)argv;
#endif
}

// What the machine (or the container) has left for all its processes: MemAvailable capped by the
// cgroup's limit; 0 when unknown. The ranks of the distributed backend on one machine share it.
inline std::uint64_t machine_available_bytes() {
  std::uint64_t avail = memory_detail::meminfo_available();
  if (const std::uint64_t cap = memory_detail::cgroup_headroom(); cap > 0)
    avail = avail > 0 ? std::min(avail, cap) : cap;
  return avail;
}

inline std::uint64_t available_memory_bytes() {
  std::uint64_t avail = machine_available_bytes();
  if (const std::uint64_t cap = memory_detail::address_space_headroom(); cap > 0)
    avail = avail > 0 ? std::min(avail, cap) : cap;
  // The system counts the heap this process keeps free as used; the process can reuse it.
  return avail > 0 ? avail + memory_detail::allocator_free_bytes() : 0;
}

}  // namespace contact3d
