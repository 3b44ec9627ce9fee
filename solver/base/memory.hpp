// What this process can still get: MemAvailable from /proc/meminfo, capped by the cgroup's memory
// limit (containers, batch schedulers) and by the address-space limit (ulimit -v) minus what the
// process already maps; 0 when unknown. Size limits follow the machine instead of a fixed number.
#pragma once

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <string>

#include <sys/resource.h>

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
inline std::uint64_t address_space_headroom() {
  rlimit lim{};
  if (getrlimit(RLIMIT_AS, &lim) != 0 || lim.rlim_cur == RLIM_INFINITY) return 0;
  std::ifstream statm("/proc/self/statm");
  std::uint64_t pages = 0;
  statm >> pages;
  const std::uint64_t used = pages * 4096;
  return lim.rlim_cur > used ? lim.rlim_cur - used : 1;
}

}  // namespace memory_detail

inline std::uint64_t available_memory_bytes() {
  std::uint64_t avail = memory_detail::meminfo_available();
  for (const std::uint64_t cap : {memory_detail::cgroup_headroom(), memory_detail::address_space_headroom()})
    if (cap > 0) avail = avail > 0 ? std::min(avail, cap) : cap;
  return avail;
}

}  // namespace contact3d
