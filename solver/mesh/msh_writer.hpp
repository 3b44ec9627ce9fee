// Writers for gmsh MSH files (ASCII): format 4.1 and format 2.2 (the one FreeFEM's gmsh plugin
// reads). Both write $PhysicalNames for every entry of Mesh::groups (in order), nodes with their
// file tags, the triangles then the tetrahedra with their element tags, in Mesh order, and
// coordinates in shortest round-trip form, so that read_msh(write(m)) == m.
//
// MSH 4.1: one entity per physical group and dimension (entity tags 1, 2, ... per dimension,
// an extra entity without physical tags for group-0 elements); each run of consecutive
// elements with the same group becomes one element block. A triangle stored once per group
// (see msh_reader.hpp) is written once per group with the same element tag.
// MSH 2.2: element tags "physical elementary", the elementary tag being that entity number.
//
// Empty node_tags / tet_tags / triangle_tags are filled with 1, 2, ... (element tags unique
// across triangles and tetrahedra); empty tet_group / triangle_group mean group 0.
// Inconsistent meshes (size mismatches, node indices out of range, non-finite coordinates)
// throw std::invalid_argument; a file that cannot be written throws InputError naming it.
#pragma once

#include <string>

#include "mesh/mesh.hpp"

namespace contact3d {

void write_msh41(const Mesh& mesh, const std::string& path);
void write_msh22(const Mesh& mesh, const std::string& path);

}  // namespace contact3d
