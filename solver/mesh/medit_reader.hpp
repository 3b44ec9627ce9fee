// Reader for the Medit mesh format that FreeFEM's savemesh writes for a mesh3: ASCII `.mesh`
// (keywords MeshVersionFormatted, Dimension 3, Vertices, Tetrahedra, Triangles, End; `#`
// comments) and binary `.meshb` (libMeshb's layout: versions 1-4, either byte order). Keeps the
// vertices, 4-node tetrahedra and 3-node triangles with their integer labels, and second-order
// ones (TetrahedraP2, TrianglesP2, as gmsh -order 2 -format mesh writes) by their corners, the
// mid-edge vertices dropped (Mesh::read_by_corner_nodes); edges, corners, ridges, required
// entities and normals are skipped; quadrilaterals, hexahedra, prisms and pyramids are rejected.
//
// Groups: every label becomes a physical group named by its number ("4"), of dimension 3 for
// tetrahedra and 2 for triangles, so a scene names them as strings: contact = ["5"].
// Malformed input raises InputError naming the file, the line (byte offset in .meshb) and the
// section.
#pragma once

#include <string>
#include <string_view>

#include "mesh/mesh.hpp"

namespace contact3d {

Mesh read_medit(const std::string& path);

// Parses .mesh or .meshb contents already in memory (binary when the first four bytes are the
// libMeshb code 1 in either byte order); `source_name` is used in error messages.
Mesh parse_medit(std::string_view contents, const std::string& source_name);

// True for paths ending in .mesh or .meshb (the Medit formats, in any letter case), false otherwise.
bool is_medit_path(const std::string& path);

// Whether the file is Medit, from its first bytes where they tell (gmsh's "$MeshFormat", Medit's
// "MeshVersionFormatted" or a '#' comment, a binary Medit code 1 in either byte order), else from its
// name (is_medit_path). A gmsh file named .mesh was read as Medit ("unknown keyword '$MeshFormat'"),
// a Medit file named .MESH as gmsh.
bool is_medit_file(const std::string& path);

}  // namespace contact3d
