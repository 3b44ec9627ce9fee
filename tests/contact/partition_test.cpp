// Partition T_H (solver/contact/partition.*): exact clipping and hat integrals against
// hand-computed polygons, a cell cut by a hole, rectangles split by a non-convex face, the
// paper's chessboard, 𝔹 row sums = cell areas, and the structural stability test (5.1).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>

#include "base/errors.hpp"
#include "contact/contact_face.hpp"
#include "contact/grid_boxes.hpp"
#include "contact/partition.hpp"
#include "fem/dof_map.hpp"
#include "mesh/brick_generator.hpp"

using namespace contact3d;

namespace {

// A flat mesh in z = 0 made of unit squares [i, i+1] x [j, j+1] (for each (i, j) in `squares`),
// each split by the diagonal (i, j)-(i+1, j+1). Group "contact" (tag 1); no tets are needed.
struct Flat {
  Mesh mesh;
  DofMap dofs;
  ContactFace face;
};

// With `coordinates`, grid line i lies at coordinates[i] (in x and in y) instead of at i.
Flat flat(const std::vector<std::pair<int, int>>& squares, const std::vector<double>& coordinates = {}) {
  Flat f;
  std::map<std::pair<int, int>, int> id;
  auto node = [&](int x, int y) {
    auto [it, fresh] = id.emplace(std::make_pair(x, y), static_cast<int>(f.mesh.nodes.size()));
    if (fresh) {
      const auto at = [&coordinates](int k) { return coordinates.empty() ? double(k) : coordinates[k]; };
      f.mesh.nodes.emplace_back(at(x), at(y), 0.0);
      f.mesh.node_tags.push_back(f.mesh.nodes.size());
    }
    return it->second;
  };
  f.mesh.groups.push_back({2, 1, "contact"});
  for (auto [i, j] : squares) {
    const int a = node(i, j), b = node(i + 1, j), c = node(i + 1, j + 1), d = node(i, j + 1);
    for (const std::array<int, 3>& t : {std::array<int, 3>{a, b, c}, std::array<int, 3>{a, c, d}}) {
      f.mesh.triangles.push_back(t);
      f.mesh.triangle_tags.push_back(f.mesh.triangles.size());
      f.mesh.triangle_group.push_back(1);
    }
  }
  f.dofs = make_dof_map(f.mesh, {});
  f.face = make_contact_face(f.mesh, {"contact"}, f.dofs);
  return f;
}

int node_at(const Mesh& m, double x, double y) {
  for (std::size_t k = 0; k < m.nodes.size(); ++k)
    if (m.nodes[k].x() == x && m.nodes[k].y() == y) return static_cast<int>(k);
  return -1;
}

double weight_of(const std::vector<std::pair<int, double>>& row, int node) {
  for (auto [n, w] : row)
    if (n == node) return w;
  return 0;
}

const ContactCell* cell_containing(const Partition& p, double x, double y) {
  for (const auto& c : p.cells)
    if (c.lo.x() <= x && x <= c.hi.x() && c.lo.y() <= y && y <= c.hi.y()) return &c;
  return nullptr;
}

void expect_row_sums_are_areas(const Flat& f, const Partition& p) {
  const auto rows = cell_node_weights(f.face, p);
  double total = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    double s = 0;
    for (auto [n, w] : rows[i]) s += w;
    EXPECT_NEAR(s, p.cells[i].area, 1e-13) << "cell " << i;
    total += p.cells[i].area;
  }
  EXPECT_NEAR(total, f.face.area, 1e-12);
}

}  // namespace

TEST(Partition, UnitSquareClippingAndHatIntegrals) {
  const Flat f = flat({{0, 0}});
  const Partition p = make_grid_partition(f.mesh, f.face, {0.5});
  ASSERT_EQ(p.cells.size(), 4u);
  for (const auto& c : p.cells) EXPECT_NEAR(c.area, 0.25, 1e-15);
  // The diagonal (0,0)-(1,1) cuts the lower-left and upper-right cells into two pieces each.
  EXPECT_EQ(cell_containing(p, 0.25, 0.25)->pieces.size(), 2u);
  EXPECT_EQ(cell_containing(p, 0.75, 0.25)->pieces.size(), 1u);
  // Cell [0.5,1] x [0,0.5] lies in the triangle (0,0),(1,0),(1,1) with hats 1-x, x-y, y:
  // integrals 0.25*(1-0.75), 0.25*(0.75-0.25), 0.25*0.25.
  const auto rows = cell_node_weights(f.face, p);
  const int k = static_cast<int>(cell_containing(p, 0.75, 0.25) - p.cells.data());
  EXPECT_NEAR(weight_of(rows[k], node_at(f.mesh, 0, 0)), 0.0625, 1e-15);
  EXPECT_NEAR(weight_of(rows[k], node_at(f.mesh, 1, 0)), 0.125, 1e-15);
  EXPECT_NEAR(weight_of(rows[k], node_at(f.mesh, 1, 1)), 0.0625, 1e-15);
  EXPECT_EQ(weight_of(rows[k], node_at(f.mesh, 0, 1)), 0.0);
  // Cell [0,0.5]^2: hat of (1,1) is y on the lower triangle and x on the upper one:
  // ∫ over {y<x} of y + ∫ over {y>x} of x = 2 * (0.5^3 / 6) = 1/24.
  const int l = static_cast<int>(cell_containing(p, 0.25, 0.25) - p.cells.data());
  EXPECT_NEAR(weight_of(rows[l], node_at(f.mesh, 1, 1)), 1.0 / 24.0, 1e-15);
  expect_row_sums_are_areas(f, p);
  EXPECT_TRUE(cells_without_own_node(f.face, p).empty());
}

// A cell's centroid is its area's: ∫x dS / area, where x = Σ x_v φ_v is P1, so ∫x dS = Σ x_v ∫φ_v dS.
// Irregular grid lines and cells of 0.7 clip the triangles into trapezoids, whose vertex average
// is not their centroid (the friction torque's arms were off by millimetres on a metre's block).
TEST(Partition, CellCentroidsAreAreaCentroids) {
  const Flat f = flat({{0, 0}, {1, 0}, {0, 1}, {1, 1}}, {0.0, 0.83, 2.1});
  const Partition p = make_grid_partition(f.mesh, f.face, {0.7});
  const auto rows = cell_node_weights(f.face, p);
  bool some_piece_is_a_trapezoid = false;
  for (std::size_t i = 0; i < p.cells.size(); ++i) {
    Eigen::Vector2d moment = Eigen::Vector2d::Zero();
    for (auto [node, w] : rows[i]) moment += w * f.mesh.nodes[node].head<2>();
    EXPECT_NEAR((p.cells[i].centroid - moment / p.cells[i].area).norm(), 0.0, 1e-13) << "cell " << i;
    for (const auto& piece : p.cells[i].pieces) some_piece_is_a_trapezoid |= piece.polygon.size() == 4;
  }
  EXPECT_TRUE(some_piece_is_a_trapezoid);
}

// Two materials side by side on Γc: no cell averages over both. A rectangle across
// their interface becomes one cell per region, and a sliver of one region goes to a neighbour of its
// own region, not into the other's cell (where a cell spans steel and rubber, the steel sinks and the
// rubber lifts with the cell's mean gap 0).
TEST(Partition, CellsDoNotSpanTwoRegions) {
  for (const auto& [width, interface, H] : {std::tuple(4, 2, 1.5), std::tuple(6, 1, 1.2)}) {
    std::vector<std::pair<int, int>> squares;
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < width; ++i) squares.push_back({i, j});
    const Flat f = flat(squares);
    std::vector<int> region;
    for (auto [i, j] : squares) region.insert(region.end(), 2, i < interface ? 0 : 1);  // two triangles each
    const Partition plain = make_grid_partition(f.mesh, f.face, {H});
    const Partition split = make_grid_partition(f.mesh, f.face, {H}, region);
    const auto spans_both = [&region](const ContactCell& c) {
      return std::any_of(c.pieces.begin(), c.pieces.end(),
                         [&](const CellPiece& p) { return region[p.triangle] == 0; }) &&
             std::any_of(c.pieces.begin(), c.pieces.end(), [&](const CellPiece& p) { return region[p.triangle] == 1; });
    };
    EXPECT_TRUE(std::any_of(plain.cells.begin(), plain.cells.end(), spans_both)) << width;  // the case is real
    EXPECT_FALSE(std::any_of(split.cells.begin(), split.cells.end(), spans_both)) << width;
    double area = 0;
    for (const auto& c : split.cells) area += c.area;
    EXPECT_NEAR(area, 2.0 * width, 1e-12);
    expect_row_sums_are_areas(f, split);
    EXPECT_TRUE(cells_without_own_node(f.face, split).empty());
  }
  const Flat f = flat({{0, 0}});
  EXPECT_THROW(make_grid_partition(f.mesh, f.face, {0.5}, {0}), std::invalid_argument);  // one per triangle
}

TEST(Partition, CellCutByAHole) {
  // 3 x 3 unit squares without the middle one: Γc has a square hole [1,2]^2.
  std::vector<std::pair<int, int>> sq;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      if (i != 1 || j != 1) sq.push_back({i, j});
  const Flat f = flat(sq);
  EXPECT_NEAR(f.face.area, 8.0, 1e-14);
  const Partition p = make_grid_partition(f.mesh, f.face, {1.5});
  ASSERT_EQ(p.cells.size(), 4u);  // each 1.5 x 1.5 rectangle minus a 0.5 x 0.5 corner of the hole
  for (const auto& c : p.cells) EXPECT_NEAR(c.area, 2.0, 1e-14);
  EXPECT_EQ(p.split_cells, 0);
  EXPECT_EQ(p.merged_slivers, 0);
  // Hat of the hole's corner (1,1) over cell [0,1.5]^2: the whole square [0,1]^2 (1/3) plus
  // two strips of width 0.5 of the neighbouring triangles, each ∫_1^1.5 (2-x)^2/2 dx = 0.875/6.
  const auto rows = cell_node_weights(f.face, p);
  const int k = static_cast<int>(cell_containing(p, 0.2, 0.2) - p.cells.data());
  EXPECT_NEAR(weight_of(rows[k], node_at(f.mesh, 1, 1)), 1.0 / 3.0 + 2 * 0.875 / 6.0, 1e-14);
  expect_row_sums_are_areas(f, p);
}

TEST(Partition, NonConvexFaceSplitsDisconnectedRectangles) {
  // Two legs [0,1]x[0,3] and [2,3]x[0,3] joined by a bridge [0,3]x[3,4]. With H = 3 the grid is
  // 1 x 2 (hy = 2): the lower rectangle holds two disconnected leg pieces and is split.
  std::vector<std::pair<int, int>> sq;
  for (int j = 0; j < 3; ++j) {
    sq.push_back({0, j});
    sq.push_back({2, j});
  }
  for (int i = 0; i < 3; ++i) sq.push_back({i, 3});
  const Flat f = flat(sq);
  const Partition p = make_grid_partition(f.mesh, f.face, {3.0});
  ASSERT_EQ(p.cells.size(), 3u);
  EXPECT_EQ(p.split_cells, 1);
  std::vector<double> areas;
  for (const auto& c : p.cells) areas.push_back(c.area);
  std::sort(areas.begin(), areas.end());
  EXPECT_NEAR(areas[0], 2.0, 1e-14);
  EXPECT_NEAR(areas[1], 2.0, 1e-14);
  EXPECT_NEAR(areas[2], 5.0, 1e-14);
  // The split cells' bounding boxes are their legs, not the rectangle.
  const ContactCell* left = cell_containing(p, 0.5, 1.0);
  ASSERT_NE(left, nullptr);
  EXPECT_NEAR(left->hi.x(), 1.0, 1e-14);
  expect_row_sums_are_areas(f, p);

  PartitionOptions whole{3.0};
  whole.split_disconnected = false;
  const Partition q = make_grid_partition(f.mesh, f.face, whole);
  ASSERT_EQ(q.cells.size(), 2u);
  EXPECT_NEAR(q.cells[0].area, 4.0, 1e-14);
}

TEST(Partition, SliverChainsMergeIntoOneNeighbour) {
  // An L: [0,4]x[0,1] plus [0,1]x[1,4]. H = 2.5 -> 2 x 2 grid with hx = hy = 2; the upper-right
  // rectangle is empty; every rectangle has area >= 2 -> nothing merged. With sliver_fraction 0.6
  // (threshold 2.4) the three rectangles of areas 3, 2, 2 merge: both arms into the corner.
  std::vector<std::pair<int, int>> sq;
  for (int i = 0; i < 4; ++i) sq.push_back({i, 0});
  for (int j = 1; j < 4; ++j) sq.push_back({0, j});
  const Flat f = flat(sq);
  const Partition p = make_grid_partition(f.mesh, f.face, {2.5});
  EXPECT_EQ(p.cells.size(), 3u);
  EXPECT_EQ(p.merged_slivers, 0);
  PartitionOptions o{2.5};
  o.sliver_fraction = 0.6;
  const Partition q = make_grid_partition(f.mesh, f.face, o);
  ASSERT_EQ(q.cells.size(), 1u);
  EXPECT_EQ(q.merged_slivers, 2);
  EXPECT_NEAR(q.cells[0].area, 7.0, 1e-14);
  EXPECT_NEAR(q.cells[0].hi.x(), 4.0, 1e-14);  // bounding box of the merged cell
  EXPECT_NEAR(q.cells[0].hi.y(), 4.0, 1e-14);
}

TEST(Partition, PaperChessboard) {
  const int n = 4;
  const Mesh mesh = make_paper_brick({n});
  const DofMap dofs = make_dof_map(mesh, {"clamped"});
  const ContactFace face = make_contact_face(mesh, {"contact"}, dofs);
  EXPECT_NEAR(face.h, 1.0 / n, 1e-14);
  const Partition p = make_grid_partition(mesh, face, {2 * face.h});
  ASSERT_EQ(static_cast<int>(p.cells.size()), (3 * n / 2) * (n / 2));
  const auto rows = cell_node_weights(face, p);
  for (std::size_t i = 0; i < p.cells.size(); ++i) {
    EXPECT_NEAR(p.cells[i].area, std::pow(2.0 / n, 2), 1e-14);
    EXPECT_EQ(p.cells[i].pieces.size(), 8u) << "cell " << i;
    double s = 0;
    for (auto [node, w] : rows[i]) s += w;
    EXPECT_NEAR(s, p.cells[i].area, 1e-14);
  }
  EXPECT_EQ(p.merged_slivers + p.split_cells + p.stability_merges, 0);
  EXPECT_TRUE(cells_without_own_node(face, p).empty());
}

TEST(Partition, StabilityViolationIsDetected) {
  const Mesh mesh = make_paper_brick({4});
  const DofMap dofs = make_dof_map(mesh, {"clamped"});
  const ContactFace face = make_contact_face(mesh, {"contact"}, dofs);
  // H = h/4: 16 cells per contact square but only one node per square: far beyond repair.
  PartitionOptions unchecked{0.25 * face.h};
  unchecked.enforce_stability = false;
  const Partition p = make_grid_partition(mesh, face, unchecked);
  const auto bad = cells_without_own_node(face, p);
  EXPECT_GE(bad.size(), p.cells.size() - face.nodes.size());
  try {
    make_grid_partition(mesh, face, {0.25 * face.h});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("(5.1)"), std::string::npos) << msg;
    EXPECT_NE(msg.find("cell "), std::string::npos) << msg;
  }
}

// Flat strip of 3 unit squares with the given nodes clamped (a "clamped" group of triangles over them).
Flat strip_with_clamped(const std::vector<std::array<int, 3>>& clamped_triangles) {
  Flat f = flat({{0, 0}, {1, 0}, {2, 0}});
  f.mesh.groups.push_back({2, 2, "clamped"});
  for (const auto& t : clamped_triangles) {
    f.mesh.triangles.push_back(t);
    f.mesh.triangle_tags.push_back(f.mesh.triangles.size());
    f.mesh.triangle_group.push_back(2);
  }
  f.dofs = make_dof_map(f.mesh, {"clamped"});
  f.face = make_contact_face(f.mesh, {"contact"}, f.dofs);
  return f;
}

TEST(Partition, LocalStabilityDefectIsRepaired) {
  // The strip's nodes (0,0), (0,1) and (1,0) clamped: the first square keeps one free node, (1,1), and
  // cells 0.5 wide put two cells on it, so one of the six has no node of its own (five free nodes):
  // a local defect (one cell), merged into its neighbour.
  const Mesh m = flat({{0, 0}, {1, 0}, {2, 0}}).mesh;
  Flat f = strip_with_clamped({{node_at(m, 0, 0), node_at(m, 0, 1), node_at(m, 1, 0)}});
  ASSERT_EQ(f.face.nodes.size(), 5u);
  EXPECT_EQ(f.face.held_triangles, 0);
  PartitionOptions o{0.5};
  o.cell_size_y = 1.0;
  o.enforce_stability = false;
  const Partition unrepaired = make_grid_partition(f.mesh, f.face, o);
  ASSERT_EQ(unrepaired.cells.size(), 6u);
  ASSERT_EQ(cells_without_own_node(f.face, unrepaired).size(), 1u);
  o.enforce_stability = true;
  const Partition p = make_grid_partition(f.mesh, f.face, o);
  ASSERT_EQ(p.cells.size(), 5u);
  EXPECT_EQ(p.stability_merges, 1);
  EXPECT_NEAR(p.cells[0].lo.x(), 0.0, 1e-14);
  EXPECT_NEAR(p.cells[0].hi.x(), 1.0, 1e-14);  // the first square's two halves, one cell
  EXPECT_TRUE(cells_without_own_node(f.face, p).empty());
  expect_row_sums_are_areas(f, p);
}

// The same defect made by a prescribed component: the nodes (0,0), (0,1) and (1,0) held in y only. A
// frictionless cell needs a node whose z is free (all eight are), so the six cells stand; with friction
// each cell's second tangential row needs a node whose y is free, five of them, and one cell is merged.
TEST(Partition, EachRowOfACellNeedsANodeWhoseComponentIsFree) {
  const Flat f = flat({{0, 0}, {1, 0}, {2, 0}});
  ComponentsHeld held{std::vector<unsigned char>(f.mesh.nodes.size(), 0), false};
  for (const auto& [x, y] : {std::pair{0.0, 0.0}, {0.0, 1.0}, {1.0, 0.0}})
    held.fixed[static_cast<std::size_t>(node_at(f.mesh, x, y))] = 1u << 1;
  PartitionOptions o{0.5};
  o.cell_size_y = 1.0;
  const Partition frictionless = make_grid_partition(f.mesh, f.face, o, {}, held);
  EXPECT_EQ(frictionless.cells.size(), 6u);
  EXPECT_EQ(frictionless.stability_merges, 0);
  held.friction = true;
  o.enforce_stability = false;
  ASSERT_EQ(cells_without_own_node(f.face, make_grid_partition(f.mesh, f.face, o, {}, held), held).size(), 1u);
  o.enforce_stability = true;
  const Partition p = make_grid_partition(f.mesh, f.face, o, {}, held);
  EXPECT_EQ(p.cells.size(), 5u);
  EXPECT_EQ(p.stability_merges, 1);
  EXPECT_TRUE(cells_without_own_node(f.face, p, held).empty());
  EXPECT_EQ(cells_without_own_node(f.face, frictionless, held).size(), 1u);
}

TEST(Partition, TrianglesHeldInEveryNodeAreLeftOutOfTheFace) {
  // The strip's nodes at x = 0 and x = 1 clamped: the first square's two triangles cannot move, so
  // they are not part of Γc (a cell over them could never have a free node, (5.1)); the rest is
  // partitioned as a strip of two squares.
  const Mesh m = flat({{0, 0}, {1, 0}, {2, 0}}).mesh;
  const int a = node_at(m, 0, 0), b = node_at(m, 0, 1), c = node_at(m, 1, 0), d = node_at(m, 1, 1);
  Flat f = strip_with_clamped({{a, b, c}, {b, c, d}});
  EXPECT_EQ(f.face.held_triangles, 2);
  EXPECT_NEAR(f.face.held_area, 1.0, 1e-14);
  EXPECT_NEAR(f.face.area, 2.0, 1e-14);
  EXPECT_NEAR(f.face.lo.x(), 1.0, 1e-14);
  ASSERT_EQ(f.face.nodes.size(), 4u);
  const Partition p = make_grid_partition(f.mesh, f.face, PartitionOptions{1.0});
  ASSERT_EQ(p.cells.size(), 2u);
  EXPECT_EQ(p.stability_merges, 0);
  expect_row_sums_are_areas(f, p);
}

TEST(Partition, FaceWithoutContactNodesIsAnInputError) {
  // Γc entirely on Γu: no contact node, no row of 𝔹 can be stable.
  Flat f = flat({{0, 0}});
  f.mesh.groups.push_back({2, 2, "clamped"});
  for (int k = 0; k < 2; ++k) {
    f.mesh.triangles.push_back(f.mesh.triangles[k]);
    f.mesh.triangle_tags.push_back(f.mesh.triangles.size());
    f.mesh.triangle_group.push_back(2);
  }
  const DofMap dofs = make_dof_map(f.mesh, {"clamped"});
  EXPECT_THROW(make_contact_face(f.mesh, {"contact"}, dofs), InputError);
}

// Aggregates for the matrix-free Newton steps' coarse space: a 7 × 5 grid of cells in blocks of
// 2 × 2 gives ⌈7/2⌉·⌈5/2⌉ = 12 aggregates of neighbouring cells, numbered without gaps; a cell of
// several rectangles (merged) goes with its first.
TEST(Partition, CellAggregatesGroupNeighbours) {
  Partition partition;
  partition.grid_nx = 7;
  partition.grid_ny = 5;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 7; ++i) {
      ContactCell cell;
      cell.pieces.push_back({0, {}, j * 7 + i});
      if (i == 1 && j == 1) cell.pieces.push_back({1, {}, j * 7 + i + 1});  // also in the next block
      partition.cells.push_back(cell);
    }
  int count = 0;
  const std::vector<int> aggregate = cell_aggregates(partition, 2, count);
  ASSERT_EQ(aggregate.size(), partition.cells.size());
  EXPECT_EQ(count, 12);
  std::map<int, int> size;
  for (int a : aggregate) {
    ASSERT_GE(a, 0);
    ASSERT_LT(a, count);
    ++size[a];
  }
  EXPECT_EQ(static_cast<int>(size.size()), count);
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 7; ++i)  // same block of 2 × 2 grid cells: same aggregate
      EXPECT_EQ(aggregate[j * 7 + i], aggregate[(j / 2 * 2) * 7 + i / 2 * 2]) << i << "," << j;
  EXPECT_NE(aggregate[0], aggregate[2]);
  int one = 0;
  EXPECT_EQ(cell_aggregates(partition, 0, one), std::vector<int>(partition.cells.size(), 0));
  EXPECT_EQ(one, 1);
}

namespace {

// A flat face on the tensor grid xs × xs split along diagonals: squares of 0.05 near the origin
// growing to 1.6 at the far corner — a contact mesh refined where the body touches.
Flat graded_flat() {
  const std::vector<double> xs{0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.6, 1.0, 1.8, 3.4};
  std::vector<std::pair<int, int>> squares;
  for (int j = 0; j + 1 < static_cast<int>(xs.size()); ++j)
    for (int i = 0; i + 1 < static_cast<int>(xs.size()); ++i) squares.push_back({i, j});
  return flat(squares, xs);
}

}  // namespace

// On a graded contact mesh, cells of "2h" follow the local element size: small where the elements
// are small, large where they are large, every cell with a node of its own, the face covered. One
// H for the whole face (twice the median extent) leaves the coarse part's cells without nodes.
TEST(Partition, GradedMeshGetsCellsFollowingItsElements) {
  const Flat f = graded_flat();
  PartitionOptions graded{2 * f.face.h_xy.x()};
  graded.cell_size_y = 2 * f.face.h_xy.y();
  graded.per_element_size = 2;
  const Partition p = make_grid_partition(f.mesh, f.face, graded);
  EXPECT_TRUE(p.graded);
  EXPECT_TRUE(cells_without_own_node(f.face, p).empty());
  expect_row_sums_are_areas(f, p);
  const ContactCell* near = cell_containing(p, 0.07, 0.07);
  const ContactCell* far = cell_containing(p, 3.0, 3.0);
  ASSERT_NE(near, nullptr);
  ASSERT_NE(far, nullptr);
  EXPECT_LE(near->hi.x() - near->lo.x(), 0.2);  // 0.75 to 1.5 times 2 × 0.05 (a merged sliver: 2 of them)
  EXPECT_GE(far->hi.x() - far->lo.x(), 1.2);    // the far elements are 1.6 wide
  EXPECT_LT(p.smallest_box.x(), 0.11);
  EXPECT_GT(p.largest_box.x(), 1.0);
  EXPECT_NE(describe_cell_sizes(p).find("following the contact mesh"), std::string::npos);

  PartitionOptions uniform = graded;
  uniform.per_element_size = 0;  // H as a length: one H everywhere
  EXPECT_THROW(make_grid_partition(f.mesh, f.face, uniform), InputError);

  // The coarse space's aggregates on graded cells: runs of 4 cells along a Z-order curve.
  int count = 0;
  const std::vector<int> aggregate = cell_aggregates(p, 2, count);
  EXPECT_EQ(count, static_cast<int>((p.cells.size() + 3) / 4));
  std::map<int, int> size;
  for (int a : aggregate) ++size[a];
  EXPECT_EQ(static_cast<int>(size.size()), count);
  for (const auto& [a, n] : size) EXPECT_LE(n, 4);
}

// A mesh that is not graded keeps the uniform grid when H is given per element: the paper's
// chessboard is the same partition with per_element_size set.
TEST(Partition, UniformMeshKeepsTheGridWhenCellsArePerElement) {
  const Mesh mesh = make_paper_brick({8});
  const DofMap dofs = make_dof_map(mesh, {"clamped"});
  const ContactFace face = make_contact_face(mesh, {"contact"}, dofs);
  PartitionOptions o{2 * face.h};
  const Partition plain = make_grid_partition(mesh, face, o);
  o.per_element_size = 2;
  const Partition per_element = make_grid_partition(mesh, face, o);
  EXPECT_FALSE(per_element.graded);
  ASSERT_EQ(per_element.cells.size(), plain.cells.size());
  for (std::size_t i = 0; i < plain.cells.size(); ++i) {
    EXPECT_EQ(per_element.cells[i].area, plain.cells[i].area);
    EXPECT_EQ(per_element.cells[i].lo, plain.cells[i].lo);
    EXPECT_EQ(per_element.cells[i].hi, plain.cells[i].hi);
  }
}

// A contact mesh refined along a line: most triangles fine, most area coarse. Counted alike its sizes
// spread by under 3 (the uniform grid, whose cells of twice the median size left most of the coarse
// area without nodes on a half-cylinder); weighted by area they spread by 50: graded.
TEST(Partition, AMeshRefinedAlongALineIsGraded) {
  std::vector<Box> triangles;
  for (int i = 0; i < 950; ++i) {  // a strip of fine ones, 1 mm
    const Eigen::Vector2d lo(0.001 * (i % 475), 0.001 * (i / 475));
    triangles.push_back({lo, lo + Eigen::Vector2d::Constant(0.001)});
  }
  for (int i = 0; i < 50; ++i) {  // the rest of the face, 5 cm
    const Eigen::Vector2d lo(0.05 * (i % 10), 0.01 + 0.05 * (i / 10));
    triangles.push_back({lo, lo + Eigen::Vector2d::Constant(0.05)});
  }
  EXPECT_TRUE(is_graded(triangles));
  // A mildly varying mesh stays uniform, counted or weighted.
  std::vector<Box> mild;
  for (int i = 0; i < 100; ++i) {
    const double size = 0.01 * (1.0 + 0.01 * i);  // 1 to 2 cm
    const Eigen::Vector2d lo(0.02 * i, 0.0);
    mild.push_back({lo, lo + Eigen::Vector2d::Constant(size)});
  }
  EXPECT_FALSE(is_graded(mild));
}
