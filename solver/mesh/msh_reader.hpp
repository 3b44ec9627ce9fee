// Reader for gmsh MSH files: format 4.1 and 2.2, each ASCII or binary (little-endian). Keeps
// nodes, 4-node tetrahedra, 3-node triangles and physical names/tags; 10-node tetrahedra and 6-node
// triangles (gmsh -order 2) by their corners, dropping the other nodes (Mesh::read_by_corner_nodes);
// other element types are skipped (points, lines) or rejected (third order and up, other volume types).
// Malformed input raises InputError naming the file and line (byte offset in binary files).
//
// Physical groups:
//  - MSH 4.1: an element's groups are the physical tags of its entity ($Entities). A triangle
//    whose entity has k physical tags is stored k times (all of the block with the first tag,
//    then all of it with the second, ...); a tetrahedron is stored once with the first tag.
//    Without $Entities, elements have group 0.
//  - MSH 2.2: the first element tag is the physical tag (0 = none). gmsh writes an element
//    once per physical group; consecutive tetrahedron records with the same nodes and the same
//    elementary tag are therefore stored once (with the first group). Binary 2.2 files follow
//    the same rules (element blocks of any size, any number of tags); their coordinates are
//    exact where gmsh's 2.2 ASCII export rounds them to 16 significant digits.
//  - Mesh::groups lists the $PhysicalNames entries in file order, then physical tags that are
//    used but unnamed (with an empty name), in order of first use.
// Unknown sections ($Periodic, $NodeData, $Comments, ...) are skipped; partitioned meshes
// ($PartitionedEntities) are rejected.
#pragma once

#include <string>
#include <string_view>

#include "mesh/mesh.hpp"

namespace contact3d {

Mesh read_msh(const std::string& path);

// Parses MSH file contents already in memory; `source_name` is used in error messages in
// place of the path.
Mesh parse_msh(std::string_view contents, const std::string& source_name);

}  // namespace contact3d
