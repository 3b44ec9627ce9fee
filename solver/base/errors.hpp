// InputError: the one exception type for anything a user supplied wrongly (mesh, scene, command
// line, an output folder that cannot be written) or asked for beyond what the machine holds. The
// CLI prints "error: <message>" and exits with code 2. The message names what to change (file,
// line, key, group, cell, value).
//
// Internal invariants (a factor of the wrong kind, a size mismatch between our own objects) throw
// std::logic_error instead: those are bugs, not user errors; the CLI still exits 2 with `error:`,
// so no run ever ends in an abort.
#pragma once

#include <stdexcept>
#include <string>

namespace contact3d {

struct InputError : std::runtime_error {
  explicit InputError(const std::string& message) : std::runtime_error(printable(message)) {}
  explicit InputError(const char* message) : InputError(std::string(message)) {}

 private:
  // Bytes quoted from a user's file (a binary file read as text, a NUL) written so that the message
  // stays one readable line: NUL as \0 (it would end what()), other control bytes and bytes that are
  // not UTF-8 as \xNN; line breaks, tabs and UTF-8 text (Γc in our own messages) as they are.
  static std::string printable(const std::string& message) {
    std::string out;
    const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(message[i]); };
    for (std::size_t i = 0; i < message.size();) {
      const unsigned char c = byte(i);
      const std::size_t length = c < 0x80                 ? 1
                                 : c >= 0xC2 && c <= 0xDF ? 2
                                 : c >= 0xE0 && c <= 0xEF ? 3
                                 : c >= 0xF0 && c <= 0xF4 ? 4
                                                          : 0;
      bool sequence = length > 1 && i + length <= message.size();
      for (std::size_t k = 1; sequence && k < length; ++k) sequence = (byte(i + k) & 0xC0) == 0x80;
      if (sequence) {
        out.append(message, i, length);
        i += length;
        continue;
      }
      if (c == '\0') {
        out += "\\0";
      } else if ((c < 0x20 && c != '\n' && c != '\t') || c >= 0x7F) {
        static const char* kHex = "0123456789abcdef";
        out += {'\\', 'x', kHex[c >> 4], kHex[c & 15]};
      } else {
        out += static_cast<char>(c);
      }
      ++i;
    }
    return out;
  }
};

}  // namespace contact3d
