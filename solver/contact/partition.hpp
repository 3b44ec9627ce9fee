// The partition T_H of Γc into cells R_i (§5): a grid of rectangles over the face's bounding
// box, each intersected with the contact triangles (exact polygon clipping). Empty cells are
// dropped; slivers (area below a fraction of a full cell) are merged into a grid neighbour.
// On the paper's brick with H = 2h and the five-tet mesh this is exactly the chessboard of
// Fig. 5 (each cell is eight contact triangles around an odd-odd node).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "contact/contact_face.hpp"
#include "contact/polygon.hpp"

namespace contact3d {

struct CellPiece {
  int triangle;     // index into ContactFace::triangles
  Polygon polygon;  // triangle ∩ rectangle, with barycentrics in that triangle
};

struct ContactCell {
  Eigen::Vector2d lo, hi;  // bounding box of the cell's pieces
  Eigen::Vector2d centroid;
  double area = 0;         // meas_2(R_i ∩ Γc)
  std::vector<CellPiece> pieces;
};

struct PartitionOptions {
  double cell_size = 0;          // H in m; the grid uses ceil(L/H) cells per direction
  double sliver_fraction = 0.2;  // cells below this fraction of a full rectangle are merged
};

struct Partition {
  std::vector<ContactCell> cells;
  int grid_nx = 0, grid_ny = 0;
  double hx = 0, hy = 0;         // actual rectangle sides (<= H)
  int merged_slivers = 0;
};

Partition make_grid_partition(const Mesh& mesh, const ContactFace& face, const PartitionOptions& options);

// For cell i: the pairs (mesh node, ∫_{R_i} φ_node dS) — the entries of one row of 𝔹 before
// the component and the sign are applied. Nodes on Γu are included.
std::vector<std::vector<std::pair<int, double>>> cell_node_weights(const ContactFace& face,
                                                                   const Partition& partition);

}  // namespace contact3d
