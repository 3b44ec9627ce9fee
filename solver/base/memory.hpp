// What this machine can still give: MemAvailable from /proc/meminfo (0 when unknown), so size
// limits follow the machine instead of a fixed number.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>

namespace contact3d {

inline std::uint64_t available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  std::uint64_t kib = 0;
  std::string unit;
  while (in >> key >> kib >> unit)
    if (key == "MemAvailable:") return kib * 1024;
  return 0;
}

}  // namespace contact3d
