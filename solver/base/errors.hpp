// InputError: the one exception type for anything a user supplied wrongly (mesh, scene,
// command line). The CLI prints "error: <message>" and exits with code 2.
#pragma once

#include <stdexcept>
#include <string>

namespace contact3d {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace contact3d
