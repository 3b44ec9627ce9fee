// InputError: the one exception type for anything a user supplied wrongly (mesh, scene, command
// line, an output folder that cannot be written) or asked for beyond what the machine holds. The
// CLI prints "error: <message>" and exits with code 2. The message names what to change (file,
// line, key, group, cell, value).
//
// Internal invariants (a factor of the wrong kind, a size mismatch between our own objects) throw
// std::logic_error instead: those are bugs, not user errors; the CLI still exits 2 with `error:`,
// so no run ever ends in an abort.
#pragma once

#include <algorithm>
#include <stdexcept>
#include <string>

namespace contact3d {

struct InputError : std::runtime_error {
  explicit InputError(const std::string& message) : std::runtime_error(printable(message)) {}
  explicit InputError(const char* message) : InputError(std::string(message)) {}

 private:
  // Bytes quoted from a user's file (a binary file read as text, a NUL) written so that the message
  // stays one readable line: NUL as \0 (it would end what()), control bytes (C0, DEL, C1) and bytes
  // that are not well-formed UTF-8 as \xNN; line breaks, tabs and UTF-8 text (Γc in our own
  // messages) as they are.
  static std::string printable(const std::string& message) {
    std::string out;
    const auto escape = [&](unsigned char c) {
      static const char* kHex = "0123456789abcdef";
      out += {'\\', 'x', kHex[c >> 4], kHex[c & 15]};
    };
    for (std::size_t i = 0; i < message.size();) {
      const auto c = static_cast<unsigned char>(message[i]);
      const std::size_t length = utf8_length(message, i);
      if (length == 1 && c == '\0') {
        out += "\\0";
      } else if (length == 1 && (c >= 0x20 || c == '\n' || c == '\t') && c != 0x7F) {
        out += static_cast<char>(c);
      } else if (length > 1 && !(c == 0xC2 && static_cast<unsigned char>(message[i + 1]) <= 0x9F)) {
        out.append(message, i, length);  // a character beyond ASCII that is not a C1 control
      } else {
        for (std::size_t k = 0; k < std::max<std::size_t>(length, 1); ++k)
          escape(static_cast<unsigned char>(message[i + k]));
      }
      i += std::max<std::size_t>(length, 1);
    }
    return out;
  }

  // The length of the well-formed UTF-8 sequence at `i` (the Unicode standard's table 3-7: no
  // overlong forms, no surrogates, nothing above U+10FFFF), 0 where none starts.
  static std::size_t utf8_length(const std::string& s, std::size_t i) {
    const auto at = [&](std::size_t k) { return k < s.size() ? static_cast<unsigned char>(s[k]) : 0u; };
    const auto in = [](unsigned b, unsigned lo, unsigned hi) { return b >= lo && b <= hi; };
    const unsigned c = at(i);
    if (c < 0x80) return 1;
    if (in(c, 0xC2, 0xDF)) return in(at(i + 1), 0x80, 0xBF) ? 2 : 0;
    if (in(c, 0xE0, 0xEF))
      return in(at(i + 1), c == 0xE0 ? 0xA0 : 0x80, c == 0xED ? 0x9F : 0xBF) && in(at(i + 2), 0x80, 0xBF) ? 3 : 0;
    if (in(c, 0xF0, 0xF4))
      return in(at(i + 1), c == 0xF0 ? 0x90 : 0x80, c == 0xF4 ? 0x8F : 0xBF) && in(at(i + 2), 0x80, 0xBF) &&
                     in(at(i + 3), 0x80, 0xBF)
                 ? 4
                 : 0;
    return 0;
  }
};

}  // namespace contact3d
