// Numbers in messages: enough significant digits that a value a user must act on is never shown
// as something else (std::to_string prints z = 1e-7 as "0.000000"); fewer for progress lines.
#pragma once

#include <cstdio>
#include <string>

namespace contact3d {

// `digits` significant digits (default 9: error messages).
inline std::string number(double v, int digits = 9) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

// A count with thousands separators: 1 037 232.
inline std::string count(long long n) {
  std::string digits = std::to_string(n < 0 ? -n : n), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ' ';
    out += digits[i];
  }
  return n < 0 ? "-" + out : out;
}

// A size in bytes, in MiB below 1 GiB and in GiB above, 3 significant digits: "5.06 MiB", "12.4 GiB".
inline std::string bytes_text(double bytes) {
  constexpr double kMiB = 1 << 20, kGiB = 1 << 30;
  return bytes < kGiB ? number(bytes / kMiB, 3) + " MiB" : number(bytes / kGiB, 3) + " GiB";
}

}  // namespace contact3d
