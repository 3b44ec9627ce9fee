// One entry point for mesh files: Medit (.mesh/.meshb, FreeFEM's savemesh) or gmsh MSH (any
// other name), each read by our own strict reader.
#pragma once

#include <string>

#include "mesh/medit_reader.hpp"
#include "mesh/mesh.hpp"
#include "mesh/msh_reader.hpp"

namespace contact3d {

inline Mesh read_mesh_file(const std::string& path) { return is_medit_path(path) ? read_medit(path) : read_msh(path); }

}  // namespace contact3d
