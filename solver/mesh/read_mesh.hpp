// One entry point for mesh files: Medit (.mesh/.meshb, FreeFEM's savemesh) or gmsh MSH, told apart
// by their first bytes (else by the name), each read by our own strict reader; a mirrored mesh (every tetrahedron
// negatively oriented) comes back reoriented.
#pragma once

#include <string>

#include "mesh/medit_reader.hpp"
#include "mesh/mesh.hpp"
#include "mesh/msh_reader.hpp"

namespace contact3d {

inline Mesh read_mesh_file(const std::string& path) {
  Mesh mesh = is_medit_file(path) ? read_medit(path) : read_msh(path);
  orient_mirrored_mesh(mesh);
  return mesh;
}

}  // namespace contact3d
