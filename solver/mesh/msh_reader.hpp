// Reader for gmsh MSH files: format 4.1 (ASCII and binary) and 2.2 (ASCII). Keeps nodes,
// 4-node tetrahedra, 3-node triangles and physical names/tags; other element types are
// skipped (points, lines) or rejected (higher order, other volume types).
// Malformed input raises InputError naming the file and line.
#pragma once

#include <string>

#include "mesh/mesh.hpp"

namespace contact3d {

Mesh read_msh(const std::string& path);

}  // namespace contact3d
