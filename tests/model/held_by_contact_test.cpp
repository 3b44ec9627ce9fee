// model/held_by_contact: the free rigid motions that the contact must hold, per part of the mesh.
#include "model/held_by_contact.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "base/errors.hpp"
#include "fem/dof_map.hpp"
#include "mesh/brick_generator.hpp"
#include "test_support.hpp"

using namespace contact3d;

// A mesh of six copies of the n = 2 brick in a row, 5 m apart, nothing prescribed: six parts, each
// with all six rigid motions free (36 in all). Each part's motions (R's columns) vanish off its own
// nodes; each part's three motions with a normal part (lift, two tilts) and three in-plane ones
// (two slides, the turn about z) are combinations of its own columns only; each part gets six pins
// among its own dofs. The description names the first four parts in full and the rest by number.
TEST(ContactHeldMotions, EachPartHasItsOwnMotionsPinsAndSplit) {
  const Mesh brick = make_paper_brick({2});
  std::vector<Eigen::Vector3d> shifts;
  for (int c = 1; c < 6; ++c) shifts.emplace_back(5.0 * c, 0, 0);
  const Mesh row = contact3d::testing::with_moved_copies(brick, shifts);
  const DofMap dofs = make_dof_map(row, {});
  const ContactHeldMotions held = contact_held_motions(row, dofs, true);
  ASSERT_EQ(held.parts.size(), 6u);
  ASSERT_EQ(held.count(), 36);
  EXPECT_EQ(held.in_plane_count(), 18);
  EXPECT_EQ(held.normal_combinations.cols(), 18);
  const int per_copy = static_cast<int>(brick.nodes.size());
  const auto part_of_dof = [&](int d) {
    for (int v = 0; v < dofs.n_nodes; ++v)
      for (int c = 0; c < 3; ++c)
        if (dofs.dof(v, c) == d) return v / per_copy;
    return -1;
  };
  for (int d = 0; d < dofs.n_free; ++d) {
    const int part = part_of_dof(d);
    for (int j = 0; j < 36; ++j) {
      if (j / 6 != part) { ASSERT_EQ(held.field(d, j), 0.0) << "dof " << d << " motion " << j; }
    }
  }
  for (int j = 0; j < 18; ++j) {
    const int part = j / 3;  // three of each kind per part, in the parts' order
    for (int i = 0; i < 36; ++i) {
      if (i / 6 != part) {
        EXPECT_EQ(held.normal_combinations(i, j), 0.0);
        EXPECT_EQ(held.in_plane_combinations(i, j), 0.0);
      }
    }
  }
  ASSERT_EQ(held.pins.size(), 36u);
  std::set<int> pins_per_part[6];
  for (const int p : held.pins) pins_per_part[part_of_dof(p)].insert(p);
  for (int part = 0; part < 6; ++part) EXPECT_EQ(pins_per_part[part].size(), 6u) << part;
  // The pinned rows of R are regular: K_s has no null space left.
  Eigen::MatrixXd pinned(36, 36);
  for (int k = 0; k < 36; ++k) pinned.row(k) = held.field.row(held.pins[static_cast<std::size_t>(k)]);
  EXPECT_EQ(Eigen::FullPivLU<Eigen::MatrixXd>(pinned).rank(), 36);

  const std::string text = held.describe();
  EXPECT_NE(text.find("part 1 of 6 ("), std::string::npos) << text;
  EXPECT_NE(text.find("part 4 of 6 ("), std::string::npos) << text;
  EXPECT_EQ(text.find("part 5 of 6"), std::string::npos) << text;
  EXPECT_NE(text.find("all six rigid motions; and 2 more parts (numbers 5, 6)"), std::string::npos) << text;
  EXPECT_NE(held.describe_in_plane().find("and 2 more parts (numbers 5, 6)"), std::string::npos);

  // The same row with the contact given up: refused, naming the first free part.
  contact3d::testing::expect_input_error([&] { contact_held_motions(row, dofs, false); },
                                         {"part 1 of 6", "no contact face"}, "free parts without contact");
}

// A one-part body keeps its messages as they were (no part label), and a part of a multi-part mesh
// with no free node on the contact face is refused by name.
TEST(ContactHeldMotions, OnePartBodyIsNamedAsBeforeAndAPartOffTheFaceIsRefused) {
  const Mesh brick = make_paper_brick({2});
  const ContactHeldMotions one = contact_held_motions(brick, make_dof_map(brick, {}), true);
  ASSERT_EQ(one.count(), 6);
  EXPECT_EQ(one.describe().find("part"), std::string::npos) << one.describe();
  EXPECT_EQ(one.describe().rfind("a translation along (1, 0, 0)", 0), 0u) << one.describe();

  const Mesh two = contact3d::testing::with_moved_copy(brick, {5, 0, 0});
  const DofMap dofs = make_dof_map(two, {});
  const ContactHeldMotions held = contact_held_motions(two, dofs, true);
  std::vector<int> first_face;  // the free dofs of the first copy's bottom nodes only
  for (int v = 0; v < static_cast<int>(brick.nodes.size()); ++v)
    if (two.nodes[v].z() == 0)
      for (int c = 0; c < 3; ++c) first_face.push_back(dofs.dof(v, c));
  contact3d::testing::expect_input_error([&] { require_free_parts_on_contact_face(held, first_face); },
                                         {"part 2 of 2", "any of its six rigid motions"}, "a part off the face");
  std::vector<int> both_faces = first_face;
  for (int v = static_cast<int>(brick.nodes.size()); v < dofs.n_nodes; ++v)
    if (two.nodes[v].z() == 0) both_faces.push_back(dofs.dof(v, 2));
  EXPECT_NO_THROW(require_free_parts_on_contact_face(held, both_faces));
}
