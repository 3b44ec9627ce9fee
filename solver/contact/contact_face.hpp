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
// direction (ContactFace::h_xy is these, at least h; FaceThickness takes them too). Zero for none.
Eigen::Vector2d median_extents(const Mesh& mesh, const std::vector<std::array<int, 3>>& triangles);

// Throws InputError if a group is missing, empty, or reaches below z = 0 (naming the triangle), or if
// every node of it is held; records nodes a condition prescribes below z = 0 (prescribed_below).
ContactFace make_contact_face(const Mesh& mesh, const std::vector<std::string>& contact_groups, const DofMap& dofs);

// The warning for face.prescribed_below (nodes a condition moves below the plane), or "" if none.
std::string prescribed_below_plane_warning(const Mesh& mesh, const ContactFace& face);

}  // namespace contact3d
