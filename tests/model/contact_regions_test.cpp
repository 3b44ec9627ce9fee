// The regions of Γc's triangles for the partition (model/contact_regions.hpp): one material has none;
// a [[material.region]] reaching the contact face splits it along the material interface; separate
// mesh parts need none (the partition keeps them apart by itself).
#include <gtest/gtest.h>

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
  const std::vector<int> one = contact_triangle_regions(same, b.mesh, b.face);
  EXPECT_EQ(std::set<int>(one.begin(), one.end()).size(), 1u);
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
