// What a mesh means, checked beyond its syntax (the readers) and its orientation (fem's
// check_tet_orientation). Each finding is an InputError naming the elements by their file tags,
// the group and what to change:
//   - a coordinate beyond ±1e15 (overflows the element integrals);
//   - two physical groups with the same name and dimension;
//   - a tetrahedron listed twice (same four nodes: it would be assembled twice), or tetrahedra that
//     overlap (through a face: a face of three, or of two on the same side of it; or face-connected
//     blocks of the mesh over each other, one's tetrahedron holding a point of another's);
//   - a boundary triangle listed twice in one group, or in two load groups (a doubled load);
//   - a contact or load (traction, pressure) triangle that is not a face of any tetrahedron, or
//     that is an interior face (shared by two); a clamped or prescribed triangle of no tetrahedron;
//   - a body below the foundation plane z = 0 (initial penetration), naming the deepest node;
//   - constraints whose nodes all lie on one line or at one point (a free rigid rotation).
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "mesh/mesh.hpp"

namespace contact3d {

// How a scene uses the mesh's groups.
struct MeshRoles {
  std::vector<std::string> clamped, contact, loaded;
  std::vector<std::string> displaced;  // groups with prescribed components (the rigid-motion check is fem's then)
  // A point of the mesh checked (in the foundation plane's frame, z = 0 the plane) in the user's
  // coordinates, for naming a node where the user will look for it; the identity where unset.
  std::function<Eigen::Vector3d(const Eigen::Vector3d&)> user_point;
};

// Coordinates beyond ±1e15 (run first: every other check computes with them).
inline constexpr double kMaxCoordinate = 1e15;
// Below the foundation plane by at most this share of the body's diagonal is rounding of the mesh's
// coordinates (8 significant digits, a float writer, a turn onto the plane), not an initial penetration:
// such nodes are taken as on the plane.
inline constexpr double kPenetrationRounding = 1e-6;
void check_coordinates_in_range(const Mesh& mesh);
// The other checks above; run after the tetrahedra are known to be positively oriented.
void check_mesh_meaning(const Mesh& mesh, const MeshRoles& roles);

// Boundary faces with another part of the mesh right outside them: volumes meshed apart that touch
// there without being joined (no shared nodes), which move as separate bodies. For a warning (they may be meant
// to be separate); the example is in file tags. Run after check_mesh_meaning.
struct FacesAgainstTheBody {
  std::size_t faces = 0;
  std::array<std::size_t, 3> example_nodes{};
  std::size_t example_against = 0;  // the tetrahedron right outside the example face
};
FacesAgainstTheBody faces_against_the_body(const Mesh& mesh);

// Tetrahedra that meet the rest of their part at nodes but share no face with it: an element laid
// over nodes of the body, or volumes meshed apart and merged at a few nodes. Load passes only through
// those nodes (a point or a line of them). The smallest such block is the example, in file tags. For a
// warning: where the block can turn about its joint, the mechanism check refuses the mesh.
struct BlocksJoinedAtNodes {
  int blocks = 0;                  // face-connected blocks beyond one per part
  std::size_t example_tets = 0;    // the example block's tetrahedra
  std::size_t example_tet = 0;     // one of them
  std::size_t example_joints = 0;  // its nodes shared with other blocks
};
BlocksJoinedAtNodes blocks_joined_at_nodes(const Mesh& mesh);

}  // namespace contact3d
