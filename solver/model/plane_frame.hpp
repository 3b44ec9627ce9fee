// A scene whose foundation plane is not z = 0 is solved in the plane's frame (contact/
// foundation_frame.hpp): the mesh and the scene's vectors (tractions and their gradients, body
// force, prescribed displacements) are rotated into it, and the result's vectors (u, its history,
// the resultant forces) rotated back. The cells, λ and the contact force's (normal, t1, t2) stay in
// the plane's frame. A per-component displacement is only meaningful there when its axis stays an
// axis (e.g. a symmetry plane x = 0 with the foundation x = 0 or z = 0): otherwise give all three
// components.
#pragma once

#include "mesh/mesh.hpp"
#include "model/scene.hpp"

namespace contact3d {

struct SolveResult;

struct PlaneFrameProblem {
  Scene scene;  // foundation: the identity
  Mesh mesh;
};

// Throws InputError for a per-component displacement whose axis is not an axis of the plane's frame.
PlaneFrameProblem to_plane_frame(const Scene& scene, const Mesh& mesh);

// u, the face history and the resultant forces of a solve in the plane's frame, back in the user's.
void result_to_user_frame(const FoundationFrame& frame, SolveResult& res);

}  // namespace contact3d
