// Which region each triangle of Γc lies in, for the partition T_H (contact/partition.hpp). A cell of
// T_H never spans two regions, because a cell's mean gap is only a fair constraint where the cell is
// alike throughout:
// - materials ([[material.region]]): a mean gap over steel and rubber lets the steel sink and the
//   rubber lift;
// - levels of the face: a triangle whose three nodes lie at one height above the foundation (a flat
//   face parallel to it, as a punch's sole) is of that level; the others (rounded edges, curved or
//   inclined faces) are of none. A cell across a flat sole's edge and its fillet averages a gap that
//   is zero on one side and grows fast on the other: the whole cell stays open and the sole's edge
//   loses its contact.
// (Separate mesh parts need no regions: their triangles share no edge, so the partition's pieces of
// two parts are never connected and never merged.)
#pragma once

#include <vector>

#include "contact/contact_face.hpp"
#include "mesh/mesh.hpp"
#include "model/scene.hpp"

namespace contact3d {

// One region number per triangle of `face` (0, 1, … in the order first met; triangles of equal
// material and level share a number); empty where the face is all one region.
std::vector<int> contact_triangle_regions(const Scene& scene, const Mesh& mesh, const ContactFace& face);

// The level of each triangle of `face`: 0, 1, … for triangles whose nodes' initial gaps agree to a
// tolerance (1e-8 of the face's extent or largest gap: the round-off of a flat face's nodes), equal for
// triangles at the same height (numbered from the lowest); kNoLevel for the others, and for a height whose
// triangles cover under 1% of the face's projected area.
inline constexpr int kNoLevel = -1;
std::vector<int> triangle_levels(const Mesh& mesh, const ContactFace& face);

}  // namespace contact3d
