// libFuzzer target for the MSH reader (solver/mesh/msh_reader.cpp): any byte string must give
// either a Mesh whose indices are in range or an InputError — never a crash, hang or other exception.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "base/errors.hpp"
#include "mesh/msh_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const contact3d::Mesh m = contact3d::parse_msh(text, "fuzz.msh");
    const auto n = static_cast<int>(m.nodes.size());
    for (const auto& t : m.tets)
      for (int v : t)
        if (v < 0 || v >= n) std::abort();  // reader returned an index out of range
    for (const auto& t : m.triangles)
      for (int v : t)
        if (v < 0 || v >= n) std::abort();
  } catch (const contact3d::InputError&) {}
  return 0;
}
