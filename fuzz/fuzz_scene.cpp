// libFuzzer target for the scene parser (parse_scene_text in solver/model/scene.cpp): any text
// must give either a Scene or an InputError. The first line of the input, when it starts with
// "--set ", is used as one override so that the override path is fuzzed too.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "model/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> overrides;
  if (text.rfind("--set ", 0) == 0) {
    const auto nl = text.find('\n');
    overrides.push_back(text.substr(6, nl == std::string::npos ? std::string::npos : nl - 6));
    text = nl == std::string::npos ? std::string() : text.substr(nl + 1);
  }
  try {
    contact3d::parse_scene_text(text, "/nonexistent", overrides);
  } catch (const contact3d::InputError&) {}
  return 0;
}
