// Tests of orient_mirrored_mesh (solver/mesh/mesh.*) and its place in read_mesh_file: a mesh whose
// every tetrahedron is negatively oriented (a mirror image) is reoriented, a tangled one is not.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "mesh/brick_generator.hpp"
#include "mesh/mesh.hpp"
#include "mesh/msh_writer.hpp"
#include "mesh/read_mesh.hpp"

namespace contact3d {
namespace {

double six_volume(const Mesh& mesh, std::size_t e) {
  const auto& t = mesh.tets[e];
  const Eigen::Vector3d& a = mesh.nodes[t[0]];
  return (mesh.nodes[t[1]] - a).dot((mesh.nodes[t[2]] - a).cross(mesh.nodes[t[3]] - a));
}

std::size_t count_negative(const Mesh& mesh) {
  std::size_t n = 0;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) n += six_volume(mesh, e) < 0;
  return n;
}

// The brick reflected through the plane y = 0: every tetrahedron turns negative.
Mesh mirrored_brick() {
  Mesh mesh = make_paper_brick({2});
  for (auto& x : mesh.nodes) x.y() = -x.y();
  return mesh;
}

TEST(MirroredMesh, EveryTetNegativeIsReorientedKeepingItsNodes) {
  Mesh mesh = mirrored_brick();
  const Mesh before = mesh;
  ASSERT_EQ(count_negative(mesh), mesh.tets.size());
  orient_mirrored_mesh(mesh);
  EXPECT_TRUE(mesh.reoriented_mirrored);
  EXPECT_EQ(count_negative(mesh), 0u);
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    EXPECT_NEAR(six_volume(mesh, e), -six_volume(before, e), 1e-15);
    auto a = mesh.tets[e], b = before.tets[e];
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b);  // the same four nodes
  }
  EXPECT_EQ(mesh.tet_tags, before.tet_tags);
  EXPECT_EQ(mesh.triangles, before.triangles);
}

TEST(MirroredMesh, PositiveAndTangledMeshesAreLeftAlone) {
  Mesh positive = make_paper_brick({2});
  const auto tets = positive.tets;
  orient_mirrored_mesh(positive);
  EXPECT_FALSE(positive.reoriented_mirrored);
  EXPECT_EQ(positive.tets, tets);
  // One tet turned inside out among positive ones: tangled, for check_tet_orientation to refuse.
  Mesh tangled = make_paper_brick({2});
  std::swap(tangled.tets[3][0], tangled.tets[3][1]);
  orient_mirrored_mesh(tangled);
  EXPECT_FALSE(tangled.reoriented_mirrored);
  EXPECT_EQ(count_negative(tangled), 1u);
  // And one positive among mirrored ones.
  Mesh mostly_mirrored = mirrored_brick();
  std::swap(mostly_mirrored.tets[5][0], mostly_mirrored.tets[5][1]);
  orient_mirrored_mesh(mostly_mirrored);
  EXPECT_FALSE(mostly_mirrored.reoriented_mirrored);
  EXPECT_EQ(count_negative(mostly_mirrored), mostly_mirrored.tets.size() - 1);
}

TEST(MirroredMesh, ReadMeshFileReorientsAMirroredFile) {
  const auto path =
      std::filesystem::temp_directory_path() / ("contact3d_mirrored_" + std::to_string(::getpid()) + ".msh");
  write_msh22(mirrored_brick(), path.string());
  const Mesh read = read_mesh_file(path.string());
  std::filesystem::remove(path);
  EXPECT_TRUE(read.reoriented_mirrored);
  EXPECT_EQ(count_negative(read), 0u);
}

}  // namespace
}  // namespace contact3d
