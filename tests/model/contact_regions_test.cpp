// The regions of Γc's triangles for the partition (model/contact_regions.hpp): one material has none;
// a [[material.region]] reaching the contact face splits it along the material interface; a flat sole
// beside a rounded or raised part splits it by level; separate mesh parts need none (the partition keeps
// them apart by itself).
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "contact/contact_face.hpp"
#include "contact/partition.hpp"
#include "fem/dof_map.hpp"
#include "mesh/brick_generator.hpp"
#include "model/contact_regions.hpp"
#include "model/scene.hpp"
#include "test_support.hpp"

using namespace contact3d;

namespace {

struct Brick {
  Mesh mesh;
  ContactFace face;
};

// The paper's brick at n = 2 with its tetrahedra left of x = `split` in a volume group "rubber".
Brick brick_with_rubber_left_of(double split) {
  Brick b{make_paper_brick({2}), {}};
  b.mesh.groups.push_back({3, 99, "rubber"});
  for (std::size_t e = 0; e < b.mesh.tets.size(); ++e) {
    double x = 0;
    for (int v : b.mesh.tets[e]) x += b.mesh.nodes[v].x() / 4;
    if (x < split) b.mesh.tet_group[e] = 99;
  }
  const DofMap dofs = make_dof_map(b.mesh, {"clamped"});
  b.face = make_contact_face(b.mesh, {"contact"}, dofs);
  return b;
}

double centroid_x(const Mesh& mesh, const std::array<int, 3>& t) {
  return (mesh.nodes[t[0]].x() + mesh.nodes[t[1]].x() + mesh.nodes[t[2]].x()) / 3;
}

// The paper's brick at n = 2 with the nodes of its bottom face (z = 0) right of x = 1.5 raised by
// lift(x); the contact face made afterwards.
template <class Lift>
Brick brick_with_bottom_raised(Lift lift) {
  Brick b{make_paper_brick({2}), {}};
  for (Eigen::Vector3d& x : b.mesh.nodes)
    if (x.z() == 0 && x.x() > 1.5 + 1e-12) x.z() = lift(x.x());
  const DofMap dofs = make_dof_map(b.mesh, {"clamped"});
  b.face = make_contact_face(b.mesh, {"contact"}, dofs);
  return b;
}

}  // namespace

TEST(ContactRegions, OneMaterialHasNone) {
  const Brick b = brick_with_rubber_left_of(1.5);
  const Scene scene = parse_scene_text(contact3d::testing::paper_scene_text(), ".");
  EXPECT_TRUE(contact_triangle_regions(scene, b.mesh, b.face).empty());
}

TEST(ContactRegions, MaterialInterfaceOnTheContactFaceSplitsIt) {
  const Brick b = brick_with_rubber_left_of(1.5);
  const Scene scene = parse_scene_text(std::string(contact3d::testing::paper_scene_text()) +
                                           "\n[[material.region]]\ngroup = \"rubber\"\nyoung = 1e7\npoisson = 0.45\n",
                                       ".");
  const std::vector<int> region = contact_triangle_regions(scene, b.mesh, b.face);
  ASSERT_EQ(region.size(), b.face.triangles.size());
  std::set<int> left, right;
  for (std::size_t t = 0; t < region.size(); ++t)
    (centroid_x(b.mesh, b.face.triangles[t]) < 1.5 ? left : right).insert(region[t]);
  ASSERT_EQ(left.size(), 1u);
  ASSERT_EQ(right.size(), 1u);
  EXPECT_NE(*left.begin(), *right.begin());

  // A region of the default material is no interface.
  const Scene same = parse_scene_text(
      std::string(contact3d::testing::paper_scene_text()) + "\n[[material.region]]\ngroup = \"rubber\"\nyoung = " +
          std::to_string(scene.material.young) + "\npoisson = " + std::to_string(scene.material.poisson) + "\n",
      ".");
  EXPECT_TRUE(contact_triangle_regions(same, b.mesh, b.face).empty());
}

// Separate parts need no regions: their contact triangles share no edge, so the partition never joins
// their pieces into one cell, even where a rectangle lies across both (two bricks side by side with
// coincident but distinct nodes at x = 3, rectangles of 6/7 across x = 3).
TEST(ContactRegions, SeparatePartsNeedNone) {
  Brick b{make_paper_brick({2}), {}};
  b.mesh = contact3d::testing::with_moved_copy(b.mesh, Eigen::Vector3d(3, 0, 0));
  const DofMap dofs = make_dof_map(b.mesh, {"clamped"});
  b.face = make_contact_face(b.mesh, {"contact"}, dofs);
  const Scene scene = parse_scene_text(contact3d::testing::paper_scene_text(), ".");
  EXPECT_TRUE(contact_triangle_regions(scene, b.mesh, b.face).empty());
  const std::size_t first_part_triangles = b.face.triangles.size() / 2;
  for (std::size_t t = 0; t < b.face.triangles.size(); ++t)  // the copy's triangles come after the original's
    ASSERT_EQ(centroid_x(b.mesh, b.face.triangles[t]) < 3, t < first_part_triangles) << t;
  const Partition p = make_grid_partition(b.mesh, b.face, {6.0 / 7});
  int across = 0;
  for (const ContactCell& c : p.cells) {
    std::set<bool> parts;
    for (const CellPiece& piece : c.pieces)
      parts.insert(static_cast<std::size_t>(piece.triangle) < first_part_triangles);
    EXPECT_EQ(parts.size(), 1u) << "a cell spans both parts";
    across += c.lo.x() < 3 - 1e-9 && c.hi.x() > 3 + 1e-9;
  }
  EXPECT_EQ(across, 0);
}

// A flat sole (x <= 1.5) beside a part that rises quadratically (a rounded edge): the sole is one level,
// the rest none, and no cell of the partition spans both, where one does without the regions.
TEST(ContactRegions, FlatSoleBesideARoundedPartSplitsIt) {
  const Brick b = brick_with_bottom_raised([](double x) { return 0.05 * (x - 1.5) * (x - 1.5); });
  const std::vector<int> level = triangle_levels(b.mesh, b.face);
  for (std::size_t t = 0; t < level.size(); ++t)
    EXPECT_EQ(level[t], centroid_x(b.mesh, b.face.triangles[t]) < 1.5 ? 0 : kNoLevel) << t;
  const Scene scene = parse_scene_text(contact3d::testing::paper_scene_text(), ".");
  const std::vector<int> region = contact_triangle_regions(scene, b.mesh, b.face);
  ASSERT_EQ(region.size(), b.face.triangles.size());
  const auto spans_both = [&](const ContactCell& c) {
    std::set<int> seen;
    for (const CellPiece& piece : c.pieces) seen.insert(level[static_cast<std::size_t>(piece.triangle)]);
    return seen.size() > 1;
  };
  const double H = 1.0;  // rectangles [1, 2] lie across x = 1.5
  const Partition plain = make_grid_partition(b.mesh, b.face, {H});
  const Partition split = make_grid_partition(b.mesh, b.face, {H}, region);
  EXPECT_TRUE(std::any_of(plain.cells.begin(), plain.cells.end(), spans_both));  // the case is real
  EXPECT_FALSE(std::any_of(split.cells.begin(), split.cells.end(), spans_both));
}

// A step: the bottom right of x = 1.5 raised by 1 cm. The triangles left of the step and those wholly
// right of it are two levels, numbered from the lowest; the triangles across the step (from x = 1.5 to
// the next column of nodes) none.
TEST(ContactRegions, TwoHeightsAreTwoLevels) {
  const Brick b = brick_with_bottom_raised([](double) { return 0.01; });
  const std::vector<int> level = triangle_levels(b.mesh, b.face);
  std::set<int> left, across, right;
  for (std::size_t t = 0; t < level.size(); ++t) {
    const auto& tri = b.face.triangles[t];
    const double lowest = std::min({b.mesh.nodes[tri[0]].x(), b.mesh.nodes[tri[1]].x(), b.mesh.nodes[tri[2]].x()});
    const double highest = std::max({b.mesh.nodes[tri[0]].x(), b.mesh.nodes[tri[1]].x(), b.mesh.nodes[tri[2]].x()});
    (highest <= 1.5 + 1e-12 ? left : lowest > 1.5 + 1e-12 ? right : across).insert(level[t]);
  }
  EXPECT_EQ(left, std::set<int>{0});
  EXPECT_EQ(right, std::set<int>{1});
  EXPECT_EQ(across, std::set<int>{kNoLevel});
}

// Round-off is no level: a flat face whose nodes' heights differ by 1e-9 m (3e-10 of its extent) is one
// region; 1e-4 m is a relief, and splits it.
TEST(ContactRegions, RoundOffOfAFlatFaceIsOneLevel) {
  const Scene scene = parse_scene_text(contact3d::testing::paper_scene_text(), ".");
  for (const double relief : {1e-9, 1e-4}) {
    int k = 0;
    const Brick b = brick_with_bottom_raised([&](double) { return relief * (++k % 2); });
    const std::vector<int> level = triangle_levels(b.mesh, b.face);
    if (relief < 1e-6) {
      EXPECT_TRUE(contact_triangle_regions(scene, b.mesh, b.face).empty()) << relief;
      EXPECT_EQ(std::set<int>(level.begin(), level.end()), std::set<int>{0}) << relief;
    } else {
      EXPECT_FALSE(contact_triangle_regions(scene, b.mesh, b.face).empty()) << relief;
      EXPECT_EQ(std::count(level.begin(), level.end(), kNoLevel) > 0, true) << relief;
    }
  }
}

// Three nodes of a curved face that happen to lie at one height make no level: the bottom of the n = 8
// brick raised as 0.01 x², one of its triangles then flattened (0.26% of the face) is still of none, so the
// face is one region.
TEST(ContactRegions, ALoneFlatTriangleOfACurvedFaceIsNoLevel) {
  Brick b{make_paper_brick({8}), {}};
  for (Eigen::Vector3d& x : b.mesh.nodes)
    if (x.z() == 0) x.z() = 0.01 * x.x() * x.x();
  const DofMap dofs = make_dof_map(b.mesh, {"clamped"});
  b.face = make_contact_face(b.mesh, {"contact"}, dofs);
  const std::array<int, 3> flattened = b.face.triangles[b.face.triangles.size() / 2];
  const double z = b.mesh.nodes[flattened[0]].z();
  for (const int v : flattened) b.mesh.nodes[v].z() = z;
  b.face = make_contact_face(b.mesh, {"contact"}, dofs);
  const std::vector<int> level = triangle_levels(b.mesh, b.face);
  EXPECT_EQ(std::count(level.begin(), level.end(), kNoLevel), static_cast<std::ptrdiff_t>(level.size()));
  const Scene scene = parse_scene_text(contact3d::testing::paper_scene_text(), ".");
  EXPECT_TRUE(contact_triangle_regions(scene, b.mesh, b.face).empty());
}

// A crowned face is no level anywhere: the bottom of the n = 8 brick raised by 0.1 mm (x − 1.5)² / 1.5²,
// nearly flat in its middle (0.7 µm across a triangle there), is one region; a tolerance of 1e-6 of the
// extent would have made a level of its middle fifth and split the face along it.
TEST(ContactRegions, ACrownedFaceIsNoLevel) {
  Brick b{make_paper_brick({8}), {}};
  for (Eigen::Vector3d& x : b.mesh.nodes)
    if (x.z() == 0) x.z() = 1e-4 * (x.x() - 1.5) * (x.x() - 1.5) / (1.5 * 1.5);
  const DofMap dofs = make_dof_map(b.mesh, {"clamped"});
  b.face = make_contact_face(b.mesh, {"contact"}, dofs);
  const std::vector<int> level = triangle_levels(b.mesh, b.face);
  EXPECT_EQ(std::count(level.begin(), level.end(), kNoLevel), static_cast<std::ptrdiff_t>(level.size()));
  const Scene scene = parse_scene_text(contact3d::testing::paper_scene_text(), ".");
  EXPECT_TRUE(contact_triangle_regions(scene, b.mesh, b.face).empty());
}
