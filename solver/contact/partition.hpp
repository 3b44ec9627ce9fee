// The partition T_H of Γc into cells R_i (§5): rectangles over the face's bounding box — a uniform
// grid, or on a graded contact mesh rectangles following its element size (grid_boxes.hpp) — each
// intersected with the contact triangles (exact polygon clipping). Then, in order:
//  1. a grid rectangle whose pieces are not connected (a hole, a gap of a non-convex face
//     between them) is split into one cell per connected component (pieces are connected when
//     they share a boundary segment of positive length and lie in the same region: two materials
//     are not averaged together, make_grid_partition's triangle_region; pieces of separate mesh
//     parts share no edge, so they are never connected);
//  2. slivers (area below a fraction of their full rectangle) are merged, smallest first, into the
//     adjacent cell of largest area (adjacent = sharing a boundary segment), repeatedly, so
//     chains of slivers end up in one cell;
//  3. the structural part of the stability condition (5.1) is enforced: 𝔹 (one row per cell
//     and component) can only have full row rank if every cell can be matched to a contact
//     node of its own (a free node whose hat function has positive integral over the cell;
//     a bipartite matching, Hall's condition). A few unmatched cells (local defects at holes,
//     corners, the edge of Γu) are merged into a neighbour; if more than
//     `max_repair_fraction` of the cells are unmatched, H is too small for the mesh and
//     make_grid_partition throws InputError naming the cells.
// On the paper's brick with H = 2h and the five-tet mesh this is exactly the chessboard of
// Fig. 5 (each cell is eight contact triangles around an odd-odd node; nothing is split or
// merged). The numerical rank of 𝔹 is still checked on Q = 𝔹K⁻¹𝔹ᵀ by the solver.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "contact/contact_face.hpp"
#include "contact/polygon.hpp"

namespace contact3d {

struct CellPiece {
  int triangle;     // index into ContactFace::triangles
  Polygon polygon;  // triangle ∩ rectangle, with barycentrics in that triangle
  int box = -1;     // grid rectangle j * grid_nx + i it was cut by
};

struct ContactCell {
  Eigen::Vector2d lo, hi;  // bounding box of the cell's pieces
  Eigen::Vector2d centroid;
  double area = 0;  // meas_2(R_i ∩ Γc)
  std::vector<CellPiece> pieces;
};

// What the rows of 𝔹 can act on at each node: a cell's normal row needs a node of its own whose z is
// free, its tangential rows (with friction) nodes whose x, resp. y, is free.
struct ComponentsHeld {
  std::vector<unsigned char> fixed;  // per mesh node: bit c set when component c is prescribed (empty: none)
  bool friction = false;             // tangential rows too

  // The components a cell's rows act on: z (normal), and x, y with friction.
  std::vector<int> row_components() const { return friction ? std::vector<int>{2, 0, 1} : std::vector<int>{2}; }
  bool is_free(int node, int component) const {
    return fixed.empty() || !(fixed[static_cast<std::size_t>(node)] >> component & 1);
  }
};

struct PartitionOptions {
  double cell_size = 0;              // H in m; the grid uses ceil(L/H) cells per direction
  double cell_size_y = 0;            // H in y when it differs (0: same as cell_size)
  double per_element_size = 0;       // k when H was given as k·h: a graded mesh then gets graded cells
  double sliver_fraction = 0.2;      // cells below this fraction of a full rectangle are merged
  bool split_disconnected = true;    // one cell per connected component of a rectangle ∩ Γc
  bool enforce_stability = true;     // repair or reject partitions failing the matching test
  double max_repair_fraction = 0.1;  // repair (5.1) by merging when at most this many cells fail
  std::string length_unit = "m";     // the scene's length unit, for messages ("mm" with mm-N-MPa)
};

struct Partition {
  std::vector<ContactCell> cells;
  int grid_nx = 0, grid_ny = 0;  // the uniform grid (graded: the coarse grid under the quadtrees)
  double hx = 0, hy = 0;         // actual rectangle sides (<= H; graded: the coarse grid's)
  bool graded = false;           // rectangles follow a graded contact mesh (grid_boxes.hpp)
  Eigen::Vector2d smallest_box = Eigen::Vector2d::Zero(), largest_box = Eigen::Vector2d::Zero();  // sides
  int merged_slivers = 0;         // cells merged into a neighbour because they were small
  int split_cells = 0;            // extra cells created by splitting disconnected rectangles
  int stability_merges = 0;       // cells merged into a neighbour to satisfy the matching test
  int regions = 1;                // regions of Γc that no cell spans (triangle_region's distinct values)
  std::string length_unit = "m";  // the unit of its lengths, for messages (PartitionOptions::length_unit)
};

// `triangle_region`: the region of each contact triangle (its tetrahedron's material and its level,
// model/contact_regions.hpp); empty: one region. A rectangle's pieces of different regions are different
// cells, and a sliver is merged into a neighbour of its own region where it has one: a cell averaging
// the gap over a stiff and a soft material lets the stiff one sink and the soft one lift (steel beside
// rubber under a prescribed push, the cell across their interface: 45 µm of 100 µm), and one across a
// flat sole's edge and its fillet stays open. `held`: what the rows of 𝔹 can act on, for the matching test
// of (5.1) (cells_without_own_node).
Partition make_grid_partition(const Mesh& mesh, const ContactFace& face, const PartitionOptions& options,
                              const std::vector<int>& triangle_region = {}, const ComponentsHeld& held = {});

// Cells grouped into aggregates of `cells_per_side` × `cells_per_side` grid rectangles (by the
// first rectangle of each cell; graded rectangles: runs of that many cells along a Z-order curve
// through their centroids) (the coarse space of the matrix-free Newton steps' two-level preconditioner,
// qp/reduced_cg.hpp): aggregate of each cell, numbered 0 .. count − 1 without gaps.
std::vector<int> cell_aggregates(const Partition& partition, int cells_per_side, int& count);

// For cell i: the pairs (mesh node, ∫_{R_i} φ_node dS) — the entries of one row of 𝔹 before
// the component and the sign are applied. Nodes on Γu are included.
std::vector<std::vector<std::pair<int, double>>> cell_node_weights(const ContactFace& face, const Partition& partition);

// The structural test of (5.1): cells that a maximum matching of cells to free contact nodes
// (face.contact_index >= 0, positive hat integral over the cell) leaves unmatched, one matching per
// row of 𝔹 a cell carries (normal; with held.friction the two tangential ones), each over the nodes
// whose component that row acts on is free (held.fixed). Empty iff Hall's condition holds for every
// row; non-empty means 𝔹 is rank deficient whatever the weights. A plane-strain slice of a cylinder
// lying on its side, held in y at both ends, graded towards its contact line: where the elements
// grew past the slice's width, cells stacked across it shared the few nodes between the ends whose y
// is free, and their y rows were dependent (refused by the numerical test at the default cells).
std::vector<int> cells_without_own_node(const ContactFace& face, const Partition& partition,
                                        const ComponentsHeld& held = {});

// "H = 0.05 x 0.05 m", or for graded cells "H from 0.01 x 0.01 to 0.08 x 0.08 m, following the contact
// mesh's element size", for messages.
std::string describe_cell_sizes(const Partition& partition);
// "; each within one of N regions of Γc by material and flat part" where `regions` > 1, else empty: the
// run's contact line and `contact3d check` append it to the cell sizes.
std::string describe_regions(int regions);

// "cell i [x0, x1] x [y0, y1], area a" for messages.
std::string describe_cell(const Partition& partition, int cell);

}  // namespace contact3d
