// One name table per enum, shared by the scene parser, `--help` and summary.json: an enum's
// names are written once, next to the enum, as a `constexpr NameTable<E, N>`.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>

namespace contact3d {

template <class E, std::size_t N>
using NameTable = std::array<std::pair<E, std::string_view>, N>;

template <class E, std::size_t N>
std::string name_of(E value, const NameTable<E, N>& names) {
  for (const auto& [v, name] : names)
    if (v == value) return std::string(name);
  return "?";
}

// The names as a list for messages: "'a', 'b' or 'c'".
template <class E, std::size_t N>
std::string names_list(const NameTable<E, N>& names) {
  std::string out;
  for (std::size_t k = 0; k < N; ++k) {
    out += (k == 0 ? "" : k + 1 == N ? " or " : ", ");
    out += "'" + std::string(names[k].second) + "'";
  }
  return out;
}

// The value named `name`; false when no entry has that name.
template <class E, std::size_t N>
bool value_of(std::string_view name, const NameTable<E, N>& names, E& value) {
  for (const auto& [v, n] : names)
    if (n == name) {
      value = v;
      return true;
    }
  return false;
}

}  // namespace contact3d
