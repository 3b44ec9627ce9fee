// Tests of check_mesh_meaning (solver/mesh/mesh_checks.*): overlapping elements (through a face, or one
// holding the centre of another) and volumes that only touch; unnamed gmsh groups go by their numbers, as
// a scene names them, so a file without $PhysicalNames (FreeFEM's savegmsh) is accepted and a name used
// twice that way is refused; held triangles of no tetrahedron; nodes below the plane.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <set>
#include <string>

#include <Eigen/Dense>

#include "base/errors.hpp"
#include "mesh/mesh_checks.hpp"
#include "mesh/msh_reader.hpp"

namespace contact3d {
namespace {

// What FreeFEM 4.9 writes for `savegmsh(cube(1, 1, 1), "g")`: MSH 2.2 without $PhysicalNames, the
// boundary labels 1-6 as physical and elementary tags, the tetrahedra in physical group 0.
const char* kFreeFemSavegmshCube = R"($MeshFormat
2.2 0 8
$EndMeshFormat
$Nodes
8
1 0 0 0
2 1 0 0
3 0 1 0
4 1 1 0
5 0 0 1
6 1 0 1
7 0 1 1
8 1 1 1
$EndNodes
$Elements
18
1 2 2 6 6 5 7 8
2 2 2 4 4 5 1 7
3 2 2 6 6 8 6 5
4 2 2 1 1 1 5 6
5 2 2 2 2 2 6 8
6 2 2 1 1 2 1 6
7 2 2 2 2 8 4 2
8 2 2 5 5 1 2 4
9 2 2 3 3 3 4 8
10 2 2 5 5 3 1 4
11 2 2 3 3 8 7 3
12 2 2 4 4 1 3 7
13 4 2 0 0 5 1 7 8
14 4 2 0 0 1 5 6 8
15 4 2 0 0 2 1 6 8
16 4 2 0 0 1 2 4 8
17 4 2 0 0 3 1 4 8
18 4 2 0 0 1 3 7 8
$EndElements
)";

// The cube of six tetrahedra with one more element added by hand, as text: "tag 4 2 0 0 n1 n2 n3 n4".
std::string cube_with_extra_tet(const std::string& element) {
  std::string text = kFreeFemSavegmshCube;
  text.replace(text.find("$Elements\n18\n"), 13, "$Elements\n19\n");
  text.replace(text.find("$EndElements"), 0, element + "\n");
  return text;
}

std::string refusal(const Mesh& mesh) {
  try {
    check_mesh_meaning(mesh, MeshRoles{{"6"}, {"5"}, {}, {}, {}});
  } catch (const InputError& e) { return e.what(); }
  return "";
}

// A tetrahedron over the top face's triangle 5-7-8, on the body's side of it like tetrahedron 13:
// the two overlap (each positively oriented, no four nodes the same).
TEST(MeshChecks, TetrahedraOnTheSameSideOfTheirSharedFaceAreRefused) {
  const Mesh mesh = parse_msh(cube_with_extra_tet("19 4 2 0 0 5 2 7 8"), "cube.msh");
  const std::string what = refusal(mesh);
  EXPECT_NE(what.find("tetrahedra 13 and 19 share the face of nodes 5, 7, 8 and lie on the same side"),
            std::string::npos)
      << what;
}

// Faces 1-6-8 (tetrahedra 14 and 15) and 1-7-8 (13 and 18) are inside the cube, one tetrahedron on
// each side; tetrahedron 6-1-7-8 is a third on both: the first in node order is named.
TEST(MeshChecks, AFaceOfThreeTetrahedraIsRefused) {
  const Mesh mesh = parse_msh(cube_with_extra_tet("19 4 2 0 0 6 1 7 8"), "cube.msh");
  const std::string what = refusal(mesh);
  EXPECT_NE(what.find("tetrahedra 14, 15 and 19 share the face of nodes 1, 6, 8"), std::string::npos) << what;
}

// The check itself on a sound mesh: each interior face has one tetrahedron on each side.
TEST(MeshChecks, TheCubesTetrahedraDoNotOverlap) {
  EXPECT_EQ(refusal(parse_msh(kFreeFemSavegmshCube, "cube.msh")), "");
}

// A triangle of the clamped group "6" that is a face of no tetrahedron (nodes 2, 3, 5) would hold the
// nodes it shares with the body in silence: refused. One inside the cube (1-4-8, shared by
// tetrahedra 16 and 17) may be held.
TEST(MeshChecks, AClampedTriangleOfNoTetrahedronIsRefused) {
  EXPECT_NE(refusal(parse_msh(cube_with_extra_tet("19 2 2 6 6 2 3 5"), "cube.msh"))
                .find("group '6' (held by boundary.clamped or boundary.displacement): 1 triangle(s) are not a face "
                      "of any tetrahedron (tags 19)"),
            std::string::npos);
  EXPECT_EQ(refusal(parse_msh(cube_with_extra_tet("19 2 2 6 6 1 4 8"), "cube.msh")), "");
}

// The cube's tetrahedra once more, over nodes of their own moved by `shift` (another volume meshed
// apart: two meshes in one file).
Mesh with_moved_copy(Mesh mesh, const Eigen::Vector3d& shift) {
  const std::size_t nodes = mesh.nodes.size(), tets = mesh.tets.size();
  for (std::size_t v = 0; v < nodes; ++v) {
    mesh.nodes.push_back(mesh.nodes[v] + shift);
    mesh.node_tags.push_back(mesh.node_tags.size() + 1);
  }
  for (std::size_t e = 0; e < tets; ++e) {
    std::array<int, 4> t = mesh.tets[e];
    for (int& v : t) v += static_cast<int>(nodes);
    mesh.tets.push_back(t);
    mesh.tet_tags.push_back(100 + e);
    mesh.tet_group.push_back(mesh.tet_group[e]);
  }
  return mesh;
}

// A volume meshed over part of another, each of its own nodes (no face shared): refused, naming a
// tetrahedron whose centre lies in one of the other volume's.
TEST(MeshChecks, VolumesMeshedOverEachOtherAreRefused) {
  const Mesh cube = parse_msh(kFreeFemSavegmshCube, "cube.msh");
  const std::string what = refusal(with_moved_copy(cube, {0.43, 0.27, 0.11}));
  EXPECT_NE(what.find("lies inside tetrahedron"), std::string::npos) << what;
  EXPECT_NE(what.find("elements overlap"), std::string::npos) << what;
}

// The same volume beside the cube, touching it along the face x = 1 without sharing its nodes, and at a
// distance: no overlap (unjoined volumes that touch are a warning of the solve, not a refusal here).
TEST(MeshChecks, VolumesThatTouchOrStandApartDoNotOverlap) {
  const Mesh cube = parse_msh(kFreeFemSavegmshCube, "cube.msh");
  EXPECT_EQ(refusal(with_moved_copy(cube, {1.0, 0.0, 0.0})), "");
  EXPECT_EQ(refusal(with_moved_copy(cube, {1.0, 0.3, 0.0})), "");
  EXPECT_EQ(refusal(with_moved_copy(cube, {3.0, 0.0, 0.0})), "");
}

// The faces the solve warns about (faces_against_the_body): the moved copy touching the cube along x = 1
// over nodes of its own has its face x = 1 against the cube, and the cube's against it (two triangles
// each: four); apart, or the cube alone, none.
TEST(MeshChecks, FacesOfPartsThatTouchWithoutSharingNodesAreFound) {
  const Mesh cube = parse_msh(kFreeFemSavegmshCube, "cube.msh");
  const FacesAgainstTheBody touching = faces_against_the_body(with_moved_copy(cube, {1.0, 0.3, 0.0}));
  EXPECT_EQ(touching.faces, 4u);
  EXPECT_EQ(faces_against_the_body(with_moved_copy(cube, {1.01, 0.3, 0.0})).faces, 0u);
  EXPECT_EQ(faces_against_the_body(cube).faces, 0u);
}

// One element over four new nodes inside the cube (a part of its own): its centre lies inside one of
// the cube's tetrahedra (off the faces they share: the six share the diagonal x = y = z, so a point on it
// is inside none of them by the margin). Over the cube's corner (node 1) instead, it is one part with the
// cube, joined at a node, and still inside it: refused too (it was left to the solve's mechanism check,
// which refuses it as a ball joint, but not the same element over three nodes).
TEST(MeshChecks, AnElementInsideTheBodyIsRefused) {
  Mesh mesh = parse_msh(kFreeFemSavegmshCube, "cube.msh");
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(0.02, 0.03, 0.01), Eigen::Vector3d(0.3, 0.12, 0.05),
                                   Eigen::Vector3d(0.1, 0.35, 0.07), Eigen::Vector3d(0.06, 0.1, 0.4)}) {
    mesh.nodes.push_back(x);
    mesh.node_tags.push_back(mesh.node_tags.size() + 1);
  }
  mesh.tets.push_back({8, 9, 10, 11});
  mesh.tet_tags.push_back(19);
  mesh.tet_group.push_back(0);
  const std::string what = refusal(mesh);
  EXPECT_NE(what.find("the centre of tetrahedron 19, (0.12, 0.15, 0.1325), lies inside tetrahedron 18"),
            std::string::npos)
      << what;
  mesh.tets.back()[0] = 0;  // over the corner
  EXPECT_NE(refusal(mesh).find("lies inside tetrahedron"), std::string::npos);
}

// An element over three nodes of the cube that form none of its faces (2, 3, 5) and one new node: one
// part with the cube, not a mechanism, and no face shared: found (the solve warns), as is one joined at the
// corner alone; the cube itself, whose six tetrahedra share faces, has no such block.
TEST(MeshChecks, AnElementJoinedAtNodesOnlyIsFound) {
  Mesh mesh = parse_msh(kFreeFemSavegmshCube, "cube.msh");
  EXPECT_EQ(blocks_joined_at_nodes(mesh).blocks, 0);
  mesh.nodes.push_back({-0.5, -0.5, -0.5});
  mesh.node_tags.push_back(9);
  mesh.tets.push_back({1, 2, 4, 8});
  mesh.tet_tags.push_back(19);
  mesh.tet_group.push_back(0);
  const BlocksJoinedAtNodes over_three = blocks_joined_at_nodes(mesh);
  EXPECT_EQ(over_three.blocks, 1);
  EXPECT_EQ(over_three.example_tets, 1u);
  EXPECT_EQ(over_three.example_tet, 19u);
  EXPECT_EQ(over_three.example_joints, 3u);
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(-0.5, 0, 0), Eigen::Vector3d(0, -0.5, 0)}) {
    mesh.nodes.push_back(x);
    mesh.node_tags.push_back(mesh.node_tags.size() + 1);
  }
  mesh.tets.back() = {0, 8, 9, 10};  // at the corner (node 1) alone
  EXPECT_EQ(blocks_joined_at_nodes(mesh).example_joints, 1u);
}

// An element laid over three nodes of the body through its inside (a triangle of no face, the fourth node
// at the cube's centre): one part with the body, joined at nodes, assembled over it — refused as an
// overlap (the search ran between parts of the mesh only, and this solved with a warning).
TEST(MeshChecks, AnElementOverNodesOfTheBodyThroughItsInsideIsAnOverlap) {
  Mesh mesh = parse_msh(kFreeFemSavegmshCube, "cube.msh");
  std::set<std::array<int, 3>> faces;
  for (const auto& t : mesh.tets)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f{};
      for (int a = 0, j = 0; a < 4; ++a)
        if (a != skip) f[j++] = t[a];
      std::sort(f.begin(), f.end());
      faces.insert(f);
    }
  mesh.nodes.push_back({0.5, 0.5, 0.5});
  mesh.node_tags.push_back(mesh.node_tags.size() + 1);
  const int centre = static_cast<int>(mesh.nodes.size()) - 1;
  std::array<int, 4> stray{};
  bool found = false;
  for (int a = 0; a < 8 && !found; ++a)
    for (int b = a + 1; b < 8 && !found; ++b)
      for (int c = b + 1; c < 8 && !found; ++c) {
        const Eigen::Vector3d n = (mesh.nodes[b] - mesh.nodes[a]).cross(mesh.nodes[c] - mesh.nodes[a]);
        const double height = n.dot(mesh.nodes[centre] - mesh.nodes[a]);
        if (faces.count({a, b, c}) || std::abs(height) < 1e-3) continue;
        stray = height > 0 ? std::array<int, 4>{a, b, c, centre} : std::array<int, 4>{a, c, b, centre};
        found = true;
      }
  ASSERT_TRUE(found);
  mesh.tets.push_back(stray);
  mesh.tet_tags.push_back(19);
  mesh.tet_group.push_back(0);
  EXPECT_EQ(blocks_joined_at_nodes(mesh).blocks, 1);
  try {
    check_mesh_meaning(mesh, MeshRoles{{"6"}, {"5"}, {}, {}, {}});
    FAIL() << "accepted an element laid through the body";
  } catch (const InputError& e) { EXPECT_NE(std::string(e.what()).find("overlap"), std::string::npos) << e.what(); }
}

TEST(MeshChecks, UnnamedGroupsOfFreeFemsSavegmshGoByTheirNumbers) {
  const Mesh mesh = parse_msh(kFreeFemSavegmshCube, "cube.msh");
  ASSERT_EQ(mesh.tets.size(), 6u);
  const PhysicalGroup* contact = mesh.find_group("5", 2);
  ASSERT_NE(contact, nullptr) << mesh.describe_groups();
  EXPECT_EQ(contact->name, "");
  EXPECT_EQ(mesh.triangles_of_group("5").size(), 2u);  // the face z = 0
  EXPECT_NO_THROW(check_mesh_meaning(mesh, MeshRoles{{"6"}, {"5"}, {"2"}, {}, {}}));
}

TEST(MeshChecks, NamedGroupAndUnnamedGroupOfTheSameNumberAreRefused) {
  std::string text = kFreeFemSavegmshCube;
  // Name physical surface 3 "4": the scene's "4" would then be both it and unnamed group 4.
  text.replace(text.find("$Nodes"), 0, "$PhysicalNames\n1\n2 3 \"4\"\n$EndPhysicalNames\n");
  const Mesh mesh = parse_msh(text, "cube.msh");
  try {
    check_mesh_meaning(mesh, MeshRoles{{"6"}, {"5"}, {}, {}, {}});
    FAIL() << "accepted two groups a scene calls '4'";
  } catch (const InputError& e) { EXPECT_NE(std::string(e.what()).find("named '4'"), std::string::npos) << e.what(); }
}

// A node that no element uses, placed below the plane (a leftover of the mesher): not part of the
// body, so not an initial penetration; a node of a tetrahedron there still is.
TEST(MeshChecks, UnusedNodeBelowThePlaneIsNotAPenetration) {
  Mesh mesh = parse_msh(kFreeFemSavegmshCube, "cube.msh");
  const MeshRoles roles{{"6"}, {"5"}, {}, {}, {}};
  mesh.nodes.emplace_back(0.5, 0.5, -0.01);
  mesh.node_tags.push_back(9);
  EXPECT_NO_THROW(check_mesh_meaning(mesh, roles));
  mesh.nodes[0].z() = -0.01;  // node 1, a vertex of the cube's tetrahedra
  try {
    check_mesh_meaning(mesh, roles);
    FAIL() << "a vertex of the body below the plane was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("node 1 at (0, 0, -0.01) lies 0.01 below"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace contact3d
