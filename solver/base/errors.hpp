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
  // A NUL quoted from a user's file would end what() there, and the message with it: written \0.
  explicit InputError(const std::string& message) : std::runtime_error(without_nul(message)) {}
  explicit InputError(const char* message) : std::runtime_error(message) {}

 private:
  static std::string without_nul(const std::string& message) {
    std::string out;
    for (const char c : message) {
      if (c == '\0')
        out += "\\0";
      else
        out += c;
    }
    return out;
  }
};

}  // namespace contact3d
