// ContactFace: the triangles of Γc (all contact groups merged) and the contact nodes: nodes of
// closure(Γc) with a free displacement component (not clamped, nor prescribed in all three
// components). Γc lies on or above the foundation plane z = 0 and is a graph over it (checked in
// mesh_checks: its outward normal points down everywhere); everything in the plane — cells,
// weights, the face's extent — uses its projection (x, y), and its height z is the initial gap d.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "fem/dof_map.hpp"
#include "mesh/mesh.hpp"

namespace contact3d {

struct ContactFace {
  std::vector<std::array<int, 3>> triangles;  // mesh node indices
  std::vector<int> nodes;                     // contact nodes (mesh indices), ascending
  std::vector<int> contact_index;             // mesh node -> position in `nodes`, or -1
  Eigen::Vector2d lo, hi;                     // bounding box of the face in (x, y)
  double h = 0;                               // typical contact edge length (median shortest edge)
  // Typical element size per direction: medians of the triangles' x- and y-extents, at least h.
  // "cell_size = 2h" uses these, so anisotropic contact meshes get matching rectangles.
  Eigen::Vector2d h_xy = Eigen::Vector2d::Zero();
  double area = 0;          // of the projection onto the plane
  std::vector<double> gap;  // mesh node -> initial gap d (height z above the plane) on Γc, else 0
  // Triangles of the contact groups whose three nodes are all held (clamped, or prescribed in every
  // component) are left out of Γc: nothing there can move, so no cell over them could be matched to a
  // node of its own (5.1); the condition holds them, and their force is in its reaction.
  int held_triangles = 0;
  double held_area = 0;   // their true area
  double rounded_up = 0;  // the deepest node below the plane within rounding (kept off the refusal), taken as on it
  // Nodes of the contact groups whose prescribed normal displacement takes them below the plane (beyond
  // rounding): how many, the deepest and by how much, and the condition that prescribes it.
  struct PrescribedBelow {
    int nodes = 0;
    int deepest = -1;
    double depth = 0;
    std::string condition;
  } prescribed_below;

  Eigen::Vector2d xy(const Mesh& mesh, int node) const { return mesh.nodes[node].head<2>(); }
};

// The medians of the triangles' x- and y-extents in the plane: their typical element size per
// direction (FaceThickness takes them). Zero for none.
Eigen::Vector2d median_extents(const Mesh& mesh, const std::vector<std::array<int, 3>>& triangles);
// The element size per direction that "2h" cells take (ContactFace::h_xy, at least h): the median
// extents, so that a mesh stretched along an axis gets rectangles of its aspect — scaled down, keeping
// their aspect, to the triangles' median area (hx·hy = 2 × area) where that is less than 0.8² of them:
// elements stretched along a direction that turns across the face (a ring's, an O-ring's line contact:
// 0.2 mm across, 1.3 mm along the ring, whose x- and y-extents are both about 0.85 mm over the quarter
// ring, made cells of 1.7 mm that the 0.55 mm wide contact zone fell inside). Near-isotropic meshes,
// about 0.9 and above, keep their extents.
inline constexpr double kTurningStretchShrink = 0.8;
Eigen::Vector2d element_sizes_xy(const Mesh& mesh, const std::vector<std::array<int, 3>>& triangles);

// Throws InputError if a group is missing, empty, or reaches below z = 0 (naming the triangle), or if
// every node of it is held; records nodes a condition prescribes below z = 0 (prescribed_below).
ContactFace make_contact_face(const Mesh& mesh, const std::vector<std::string>& contact_groups, const DofMap& dofs);

// The warning for face.prescribed_below (nodes a condition moves below the plane), or "" if none.
std::string prescribed_below_plane_warning(const Mesh& mesh, const ContactFace& face);

}  // namespace contact3d
