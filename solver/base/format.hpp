// Numbers in messages: enough significant digits that a value a user must act on is never shown
// as something else (std::to_string prints z = 1e-7 as "0.000000").
#pragma once

#include <cstdio>
#include <string>

namespace contact3d {

inline std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace contact3d
