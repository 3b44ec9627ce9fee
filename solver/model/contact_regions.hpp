// Which region each triangle of Γc lies in, for the partition T_H (contact/partition.hpp): its
// tetrahedron's material ([[material.region]]). A cell of T_H never spans two regions: a mean gap over
// steel and rubber lets the steel sink and the rubber lift. (Separate mesh parts need no regions: their
// triangles share no edge, so the partition's pieces of two parts are never connected and never merged.)
#pragma once

#include <vector>

#include "contact/contact_face.hpp"
#include "mesh/mesh.hpp"
#include "model/scene.hpp"

namespace contact3d {

// One region number per triangle of `face` (0, 1, … in the order first met; equal materials share a
// number); empty where the scene has no [[material.region]].
std::vector<int> contact_triangle_regions(const Scene& scene, const Mesh& mesh, const ContactFace& face);

}  // namespace contact3d
