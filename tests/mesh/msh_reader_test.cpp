// Tests of the gmsh MSH reader and writers (solver/mesh/msh_reader.*, msh_writer.*).
// Fixtures: meshes/fixtures/brick_n2_* (geo/brick.geo, n = 2, written by gmsh), and pairs of
// MSH 2.2 ASCII / binary exports of the same meshes (gmsh 4.8.4, from /work/main):
//   gmsh -3 -format msh22 -bin -setnumber n 2 geo/brick.geo -o meshes/fixtures/brick_n2_msh22_bin.msh
//   gmsh -3 -format msh22 [-bin] -setnumber h 0.5 geo/holed.geo -o meshes/fixtures/holed_h05_msh22[_bin].msh
//   gmsh -3 -format msh22 [-bin] meshes/fixtures/multigroup.geo -o meshes/fixtures/multigroup_msh22[_bin].msh
// (gmsh meshes these deterministically: two runs give byte-identical files.)
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "mesh/mesh.hpp"
#include "mesh/msh_reader.hpp"
#include "mesh/msh_writer.hpp"

namespace contact3d {
namespace {

namespace fs = std::filesystem;
using Tet = std::array<int, 4>;

const std::string kFixtures = std::string(CONTACT3D_SOURCE_DIR) + "/meshes/fixtures/";
const std::string kAscii41 = kFixtures + "brick_n2_msh41.msh";
const std::string kBinary41 = kFixtures + "brick_n2_msh41_bin.msh";
const std::string kPartitioned41 = kFixtures + "brick_n2_msh41_part2.msh";
const std::string kPartitionedGhosts41 = kFixtures + "brick_n2_msh41_part3_ghosts_bin.msh";
const std::string kAscii22 = kFixtures + "brick_n2_msh22.msh";
const std::string kBinary22 = kFixtures + "brick_n2_msh22_bin.msh";
const std::string kHoledAscii22 = kFixtures + "holed_h05_msh22.msh";
const std::string kHoledBinary22 = kFixtures + "holed_h05_msh22_bin.msh";
const std::string kMultiAscii22 = kFixtures + "multigroup_msh22.msh";
const std::string kMultiBinary22 = kFixtures + "multigroup_msh22_bin.msh";
constexpr int kN = 2;  // brick.geo parameter of the fixtures

// A scratch directory removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("contact3d_msh_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::string write(const std::string& name, const std::string& contents) const {
    const std::string p = file(name);
    std::ofstream(p, std::ios::binary) << contents;
    return p;
  }

 private:
  fs::path path_;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in) << path;
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Runs f, which must throw InputError; returns the message.
std::string input_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) { return e.what(); } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return {};
}

void expect_same_mesh(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (std::size_t i = 0; i < a.nodes.size(); ++i)
    for (int k = 0; k < 3; ++k) ASSERT_EQ(a.nodes[i][k], b.nodes[i][k]) << "node " << i;
  EXPECT_EQ(a.node_tags, b.node_tags);
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.tet_tags, b.tet_tags);
  EXPECT_EQ(a.tet_group, b.tet_group);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.triangle_tags, b.triangle_tags);
  EXPECT_EQ(a.triangle_group, b.triangle_group);
  ASSERT_EQ(a.groups.size(), b.groups.size());
  for (std::size_t i = 0; i < a.groups.size(); ++i) {
    EXPECT_EQ(a.groups[i].dim, b.groups[i].dim);
    EXPECT_EQ(a.groups[i].tag, b.groups[i].tag);
    EXPECT_EQ(a.groups[i].name, b.groups[i].name);
  }
}

double tet_volume(const Mesh& m, const std::array<int, 4>& t) {
  const Eigen::Vector3d& a = m.nodes[t[0]];
  Eigen::Matrix3d d;
  d << m.nodes[t[1]] - a, m.nodes[t[2]] - a, m.nodes[t[3]] - a;
  return d.determinant() / 6;
}

// The brick (0,3)x(0,1)x(0,1) of geo/brick.geo meshed with parameter n.
void check_brick(const Mesh& m, int n) {
  EXPECT_EQ(m.nodes.size(), static_cast<std::size_t>((3 * n + 1) * (n + 1) * (n + 1)));
  EXPECT_EQ(m.node_tags.size(), m.nodes.size());
  ASSERT_EQ(m.tets.size(), static_cast<std::size_t>(6 * 3 * n * n * n));
  EXPECT_EQ(m.tet_tags.size(), m.tets.size());
  ASSERT_EQ(m.tet_group.size(), m.tets.size());

  const char* surfaces[] = {"clamped", "load_end", "load_top", "contact", "free"};
  ASSERT_EQ(m.groups.size(), 6u) << m.describe_groups();
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(m.groups[i].name, surfaces[i]);
    EXPECT_EQ(m.groups[i].dim, 2);
    EXPECT_EQ(m.groups[i].tag, i + 1);
  }
  const PhysicalGroup* body = m.find_group("body", 3);
  ASSERT_NE(body, nullptr);
  for (int g : m.tet_group) ASSERT_EQ(g, body->tag);

  double volume = 0;
  for (const auto& t : m.tets) {
    const double v = tet_volume(m, t);
    ASSERT_GT(std::abs(v), 1e-12);
    volume += std::abs(v);
  }
  EXPECT_NEAR(volume, 3.0, 1e-12);

  ASSERT_EQ(m.triangle_tags.size(), m.triangles.size());
  ASSERT_EQ(m.triangle_group.size(), m.triangles.size());
  const std::vector<int> contact = m.triangles_of_group("contact");
  EXPECT_EQ(contact.size(), static_cast<std::size_t>(2 * 3 * n * n));
  double contact_area = 0;
  for (int i : contact) {
    for (int v : m.triangles[i]) ASSERT_EQ(m.nodes[v].z(), 0.0) << "contact triangle " << i;
    contact_area += triangle_area(m, m.triangles[i]);
  }
  EXPECT_NEAR(contact_area, 3.0, 1e-12);
  EXPECT_EQ(m.triangles_of_group("clamped").size(), static_cast<std::size_t>(2 * n * n));
  EXPECT_EQ(m.triangles_of_group("load_end").size(), static_cast<std::size_t>(2 * n * n));
  EXPECT_EQ(m.triangles_of_group("load_top").size(), static_cast<std::size_t>(2 * 3 * n * n));
  EXPECT_EQ(m.triangles_of_group("free").size(), static_cast<std::size_t>(2 * 2 * 3 * n * n));
  for (int i : m.triangles_of_group("clamped"))
    for (int v : m.triangles[i]) ASSERT_EQ(m.nodes[v].x(), 0.0);
  double area = 0;
  for (const auto& t : m.triangles) area += triangle_area(m, t);
  EXPECT_NEAR(area, 14.0, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// gmsh-generated files

TEST(MshReader, Gmsh41Ascii) {
  const Mesh m = read_msh(kAscii41);
  check_brick(m, kN);
  // gmsh numbers the nodes 1..N here.
  for (std::size_t i = 0; i < m.node_tags.size(); ++i) EXPECT_EQ(m.node_tags[i], i + 1);
}

TEST(MshReader, Gmsh41BinaryMatchesAscii) {
  const Mesh m = read_msh(kBinary41);
  check_brick(m, kN);
  expect_same_mesh(m, read_msh(kAscii41));
}

TEST(MshReader, Gmsh22MatchesAscii) {
  const Mesh m = read_msh(kAscii22);
  check_brick(m, kN);
  expect_same_mesh(m, read_msh(kAscii41));
}

// A mesh as sets of node tags: tets, and triangles per group name (file order aside).
std::map<std::string, std::multiset<std::vector<std::size_t>>> elements_by_tags(const Mesh& m) {
  std::map<std::string, std::multiset<std::vector<std::size_t>>> out;
  const auto tags = [&](const auto& element) {
    std::vector<std::size_t> t;
    for (int v : element) t.push_back(m.node_tags[static_cast<std::size_t>(v)]);
    std::sort(t.begin(), t.end());
    return t;
  };
  for (const auto& tet : m.tets) out["tets"].insert(tags(tet));
  for (const PhysicalGroup& g : m.groups)
    if (g.dim == 2)
      for (int i : m.triangles_of_group(g.name)) out[g.name].insert(tags(m.triangles[static_cast<std::size_t>(i)]));
  return out;
}

// gmsh -part N: the blocks refer to $PartitionedEntities' pieces, whose physical tags are the
// parent's; the interfaces between partitions (surfaces inside the body) are dropped. The same
// brick as unpartitioned: node coordinates by tag, tets and each group's triangles.
TEST(MshReader, Gmsh41PartitionedMatchesUnpartitioned) {
  const Mesh plain = read_msh(kAscii41);
  std::map<std::size_t, Eigen::Vector3d> plain_nodes;
  for (std::size_t i = 0; i < plain.nodes.size(); ++i) plain_nodes[plain.node_tags[i]] = plain.nodes[i];
  for (const std::string& file : {kPartitioned41, kPartitionedGhosts41}) {
    SCOPED_TRACE(file);
    const Mesh m = read_msh(file);
    check_brick(m, kN);
    EXPECT_EQ(m.triangles.size(), plain.triangles.size());  // no interface triangle kept
    for (std::size_t i = 0; i < m.nodes.size(); ++i) EXPECT_EQ(m.nodes[i], plain_nodes.at(m.node_tags[i]));
    EXPECT_EQ(elements_by_tags(m), elements_by_tags(plain));
  }
}

// gmsh -part 2 -part_split: a file holds one partition, a piece of the body: refused.
TEST(MshReader, OnePartitionOfSeveralIsRefused) {
  const std::string msg = input_error([] { read_msh(kFixtures + "brick_n2_msh41_part2_split_1.msh"); });
  EXPECT_NE(msg.find("partitioned into 2 parts"), std::string::npos) << msg;
  EXPECT_NE(msg.find("partition(s) 1 only"), std::string::npos) << msg;
  EXPECT_NE(msg.find("-part_split"), std::string::npos) << msg;
}

TEST(MshReader, ParseFromMemoryMatchesFile) {
  expect_same_mesh(parse_msh(slurp(kBinary41), "brick"), read_msh(kBinary41));
}

// ---------------------------------------------------------------------------------------------
// Writers

TEST(MshWriter, RoundTripBrick) {
  TempDir dir;
  for (const std::string& fixture : {kAscii41, kBinary41, kAscii22, kBinary22}) {
    SCOPED_TRACE(fixture);
    const Mesh m = read_msh(fixture);
    write_msh41(m, dir.file("b41.msh"));
    write_msh22(m, dir.file("b22.msh"));
    expect_same_mesh(read_msh(dir.file("b41.msh")), m);
    expect_same_mesh(read_msh(dir.file("b22.msh")), m);
  }
}

// A mesh exercising what the writers must preserve: sparse node tags, doubles that need all 17
// digits, a triangle in two groups, elements without a group, unnamed and lower-dim groups.
Mesh tricky_mesh() {
  Mesh m;
  m.nodes = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1.0 / 3, 0.1 + 0.2, -1e-300),
             Eigen::Vector3d(-0.0, std::acos(-1.0), 4.9406564584124654e-324),
             Eigen::Vector3d(1e300, -2.5, 123456789.123456789), Eigen::Vector3d(1, 1, 1)};
  m.node_tags = {7, 3, 1000000007, 42, 8};
  m.tets = {{0, 1, 2, 3}, {1, 2, 3, 4}, {0, 2, 1, 4}};
  m.tet_tags = {100, 50, 51};
  m.tet_group = {6, 0, 6};
  m.triangles = {{0, 1, 2}, {1, 2, 3}, {0, 1, 2}, {2, 3, 4}};
  m.triangle_tags = {11, 12, 11, 13};
  m.triangle_group = {4, 0, 9, 4};
  m.groups = {{2, 4, "contact"}, {3, 6, "body with spaces"}, {2, 9, ""}, {1, 5, "edge \"quoted\""}, {0, 3, "pt"}};
  return m;
}

TEST(MshWriter, RoundTripPreservesTagsGroupsAndDoubles) {
  TempDir dir;
  const Mesh m = tricky_mesh();
  write_msh41(m, dir.file("t41.msh"));
  write_msh22(m, dir.file("t22.msh"));
  const Mesh a = read_msh(dir.file("t41.msh"));
  const Mesh b = read_msh(dir.file("t22.msh"));
  expect_same_mesh(a, m);
  expect_same_mesh(b, m);
  EXPECT_EQ(a.triangles_of_group(""), std::vector<int>({2}));
  EXPECT_EQ(a.triangles_of_group("contact"), std::vector<int>({0, 3}));
  // Writing what was read gives the same file.
  write_msh41(a, dir.file("again41.msh"));
  EXPECT_EQ(slurp(dir.file("again41.msh")), slurp(dir.file("t41.msh")));
}

TEST(MshWriter, Msh41HasOneEntityPerPhysicalGroup) {
  TempDir dir;
  write_msh41(read_msh(kAscii41), dir.file("b.msh"));
  const std::string text = slurp(dir.file("b.msh"));
  // 5 surface groups, 1 volume group; no points or curves.
  EXPECT_NE(text.find("$Entities\n0 0 5 1\n"), std::string::npos) << text.substr(0, 400);
  EXPECT_NE(text.find("2 4 \"contact\"\n"), std::string::npos);
  // Element blocks follow runs of equal groups, so the triangle order is kept: "free" is one
  // entity but two blocks (6 triangle blocks and 1 tetrahedron block).
  EXPECT_NE(text.find("$Elements\n7 256 1 256\n"), std::string::npos);
}

TEST(MshWriter, FillsMissingTags) {
  TempDir dir;
  Mesh m;
  m.nodes = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)};
  m.tets = {{0, 1, 2, 3}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}};
  for (auto writer : {&write_msh41, &write_msh22}) {
    writer(m, dir.file("m.msh"));
    const Mesh r = read_msh(dir.file("m.msh"));
    EXPECT_EQ(r.node_tags, std::vector<std::size_t>({1, 2, 3, 4}));
    EXPECT_EQ(r.triangle_tags, std::vector<std::size_t>({1, 2}));
    EXPECT_EQ(r.tet_tags, std::vector<std::size_t>({3}));
    EXPECT_EQ(r.tet_group, std::vector<int>({0}));
    EXPECT_EQ(r.triangle_group, std::vector<int>({0, 0}));
    EXPECT_EQ(r.tets, m.tets);
    EXPECT_EQ(r.triangles, m.triangles);
    EXPECT_TRUE(r.groups.empty());
  }
  // Nodes only, and an empty mesh.
  Mesh nodes_only;
  nodes_only.nodes = m.nodes;
  write_msh41(nodes_only, dir.file("n.msh"));
  EXPECT_EQ(read_msh(dir.file("n.msh")).nodes.size(), 4u);
  write_msh41(Mesh{}, dir.file("e41.msh"));
  write_msh22(Mesh{}, dir.file("e22.msh"));
  EXPECT_TRUE(read_msh(dir.file("e41.msh")).nodes.empty());
  EXPECT_TRUE(read_msh(dir.file("e22.msh")).tets.empty());
}

TEST(MshWriter, RejectsInconsistentMeshAndUnwritablePath) {
  TempDir dir;
  Mesh m = tricky_mesh();
  m.tet_group.pop_back();
  EXPECT_THROW(write_msh41(m, dir.file("x.msh")), std::invalid_argument);
  m = tricky_mesh();
  m.triangles[1][2] = 5;
  EXPECT_THROW(write_msh22(m, dir.file("x.msh")), std::invalid_argument);
  m = tricky_mesh();
  m.nodes[2].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(write_msh41(m, dir.file("x.msh")), std::invalid_argument);
  const std::string bad = dir.file("no/such/dir/out.msh");
  const std::string msg = input_error([&] { write_msh41(tricky_mesh(), bad); });
  EXPECT_NE(msg.find(bad), std::string::npos) << msg;
}

// ---------------------------------------------------------------------------------------------
// Hand-written valid files

TEST(MshReader, EntityWithSeveralPhysicalTags) {
  const std::string text =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
      "$PhysicalNames\n3\n2 4 \"contact\"\n2 7 \"also\"\n3 6 \"body\"\n$EndPhysicalNames\n"
      "$Entities\n0 0 1 1\n"
      "1 0 0 0 1 1 0 2 4 7 0\n"
      "1 0 0 0 1 1 1 2 6 9 0\n"
      "$EndEntities\n"
      "$Nodes\n1 5 1 5\n3 1 0 5\n1\n2\n3\n4\n5\n"
      "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n$EndNodes\n"
      "$Elements\n2 4 1 4\n"
      "2 1 2 2\n1 1 2 3\n2 1 3 5\n"
      "3 1 4 2\n3 1 2 3 4\n4 2 3 4 5\n"
      "$EndElements\n";
  const Mesh m = parse_msh(text, "multi.msh");
  // Triangles: the block once per physical tag, block after block.
  using Tri = std::array<int, 3>;
  EXPECT_EQ(m.triangles, std::vector<Tri>({{0, 1, 2}, {0, 2, 4}, {0, 1, 2}, {0, 2, 4}}));
  EXPECT_EQ(m.triangle_tags, std::vector<std::size_t>({1, 2, 1, 2}));
  EXPECT_EQ(m.triangle_group, std::vector<int>({4, 4, 7, 7}));
  EXPECT_EQ(m.triangles_of_group("also"), std::vector<int>({2, 3}));
  // Tetrahedra: once, in the first physical group and, by tet_extra_groups, in the other.
  EXPECT_EQ(m.tets.size(), 2u);
  EXPECT_EQ(m.tet_group, std::vector<int>({6, 6}));
  EXPECT_EQ(m.tet_tags, std::vector<std::size_t>({3, 4}));
  using Extra = std::pair<std::size_t, int>;
  EXPECT_EQ(m.tet_extra_groups, std::vector<Extra>({{0, 9}, {1, 9}}));
  EXPECT_EQ(m.tets_of_group(9), std::vector<std::size_t>({0, 1}));
  EXPECT_EQ(m.tets_of_group(6), std::vector<std::size_t>({0, 1}));
  // Named groups in file order, then the unnamed physical tag 9.
  ASSERT_EQ(m.groups.size(), 4u);
  EXPECT_EQ(m.groups[3].dim, 3);
  EXPECT_EQ(m.groups[3].tag, 9);
  EXPECT_EQ(m.groups[3].name, "");
}

// gmsh's -save_all in MSH 2.2 writes every element with physical tag 0 beside the $PhysicalNames it
// still lists: refused at reading with what to do, instead of "contact group has no triangles" later.
TEST(MshReader, SaveAll22WithoutPhysicalTagsIsRefused) {
  const std::string text =
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
      "$PhysicalNames\n2\n2 1 \"contact\"\n3 2 \"body\"\n$EndPhysicalNames\n"
      "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n"
      "$Elements\n2\n1 2 2 0 1 1 2 3\n2 4 2 0 1 1 2 3 4\n$EndElements\n";
  const std::string msg = input_error([&] { parse_msh(text, "saveall.msh"); });
  EXPECT_NE(msg.find("every element has physical tag 0"), std::string::npos) << msg;
  EXPECT_NE(msg.find("SaveAll"), std::string::npos) << msg;
  EXPECT_NE(msg.find("line 20:"), std::string::npos) << msg;  // the last of its 20 lines, not the one after
  std::string tagged = text;                                  // the same elements in their groups: read
  tagged.replace(tagged.find("\n1 2 2 0 1"), 10, "\n1 2 2 1 1");
  tagged.replace(tagged.find("\n2 4 2 0 1"), 10, "\n2 4 2 2 1");
  const Mesh m = parse_msh(tagged, "tagged.msh");
  EXPECT_EQ(m.tets_of_group(2).size(), 1u);
  EXPECT_EQ(m.triangles_of_group("contact").size(), 1u);
}

// Sparse node tags (sparse map), parametric nodes, points and lines (skipped), sections the
// reader does not know ($Comments, $NodeData, $Periodic), no $PhysicalNames.
const char* kSparse41 =
    "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
    "$Comments\nanything, even $Nodes\n$EndComments\n"
    "$Entities\n1 1 1 1\n"
    "5 0 0 0 0\n"
    "3 0 0 0 1 0 0 0 2 5 -5\n"
    "2 0 0 0 1 1 0 0 0\n"
    "1 0 0 0 1 1 1 0 0\n"
    "$EndEntities\n"
    "$Nodes\n3 5 7 1000000007\n"
    "0 5 0 1\n1000000007\n0 0 0\n"
    "2 2 1 2\n7\n42\n1 0 0 0.5 0.5\n0 1 0 0.25 0.25\n"
    "3 1 0 2\n8\n9\n0 0 1\n1 1 1\n"
    "$EndNodes\n"
    "$Elements\n3 4 1 40\n"
    "0 5 15 1\n40 1000000007\n"
    "1 3 1 1\n30 1000000007 7\n"
    "3 1 4 2\n10 1000000007 7 42 8\n11 7 42 8 9\n"
    "$EndElements\n"
    "$NodeData\n1\n\"temperature\"\n1\n0.0\n3\n0\n1\n5\n7 1.0\n42 2.0\n8 3.0\n9 4.0\n1000000007 5.0\n"
    "$EndNodeData\n"
    "$Periodic\n0\n$EndPeriodic\n";

void check_sparse(const Mesh& m) {
  EXPECT_EQ(m.node_tags, std::vector<std::size_t>({1000000007, 7, 42, 8, 9}));
  EXPECT_EQ(m.nodes[2], Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(m.tets, std::vector<Tet>({{0, 1, 2, 3}, {1, 2, 3, 4}}));
  EXPECT_EQ(m.tet_tags, std::vector<std::size_t>({10, 11}));
  EXPECT_EQ(m.tet_group, std::vector<int>({0, 0}));
  EXPECT_TRUE(m.triangles.empty());
  EXPECT_TRUE(m.groups.empty());
}

TEST(MshReader, SparseTagsParametricNodesAndUnknownSections) { check_sparse(parse_msh(kSparse41, "sparse.msh")); }

TEST(MshReader, WindowsLineEndingsAndTrailingBlanks) {
  std::string crlf;
  for (const char* c = kSparse41; *c; ++c) {
    if (*c == '\n') crlf += " \t\r";
    crlf += *c;
  }
  check_sparse(parse_msh(crlf, "crlf.msh"));
}

// gmsh -order 2: a 10-node tet and a 6-node triangle are read by their corners (listed first), the
// mid-edge nodes dropped and the corners renumbered in file order, their tags kept; 3-node lines
// are skipped as 2-node ones are.
TEST(MshReader, SecondOrderElementsAreReadByTheirCorners) {
  const std::string text =
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
      "$Nodes\n10\n1 0 0 0\n2 0.5 0 0\n3 1 0 0\n4 0 0.5 0\n5 0 1 0\n6 0 0 0.5\n7 0 0 1\n"
      "8 0.5 0.5 0\n9 0.5 0 0.5\n10 0 0.5 0.5\n$EndNodes\n"
      "$Elements\n3\n"
      "1 8 2 0 1 1 3 2\n"
      "2 9 2 4 1 1 3 5 2 8 4\n"
      "3 11 2 6 1 1 3 5 7 2 8 4 6 10 9\n"
      "$EndElements\n";
  const Mesh m = parse_msh(text, "p2.msh");
  EXPECT_TRUE(m.read_by_corner_nodes);
  EXPECT_EQ(m.nodes.size(), 4u);
  EXPECT_EQ(m.node_tags, std::vector<std::size_t>({1, 3, 5, 7}));
  EXPECT_EQ(m.nodes[3], Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(m.tets, std::vector<Tet>({{0, 1, 2, 3}}));
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.triangles[0], (std::array<int, 3>{0, 1, 2}));
  EXPECT_EQ(m.triangle_group, std::vector<int>({4}));
  EXPECT_FALSE(parse_msh(std::string("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n"
                                     "4 0 0 1\n$EndNodes\n$Elements\n1\n1 4 2 6 1 1 2 3 4\n$EndElements\n"),
                         "p1.msh")
                   .read_by_corner_nodes);
}

TEST(MshReader, Msh22DuplicateTetLinesAreStoredOnce) {
  const std::string text =
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
      "$PhysicalNames\n3\n2 4 \"contact\"\n2 7 \"also\"\n3 6 \"body\"\n$EndPhysicalNames\n"
      "$Nodes\n5\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n50 1 1 1\n$EndNodes\n"
      "$Elements\n8\n"
      "1 15 2 0 1 10\n"
      "2 1 2 0 3 10 20\n"
      "3 2 2 4 1 10 20 30\n"
      "4 2 2 7 1 10 20 30\n"
      "5 4 2 6 1 10 20 30 40\n"
      "6 4 2 9 1 10 20 30 40\n"
      "7 4 2 6 1 20 30 40 50\n"
      "8 2 3 4 1 0 20 30 40\n"
      "$EndElements\n";
  const Mesh m = parse_msh(text, "dup.msh");
  EXPECT_EQ(m.tets, std::vector<Tet>({{0, 1, 2, 3}, {1, 2, 3, 4}}));
  EXPECT_EQ(m.tet_tags, std::vector<std::size_t>({5, 7}));
  EXPECT_EQ(m.tet_group, std::vector<int>({6, 6}));
  EXPECT_EQ(m.triangle_tags, std::vector<std::size_t>({3, 4, 8}));
  EXPECT_EQ(m.triangle_group, std::vector<int>({4, 7, 4}));
  ASSERT_EQ(m.groups.size(), 4u);
  EXPECT_EQ(m.groups[3].tag, 9);
  EXPECT_EQ(m.groups[3].name, "");
}

// ---------------------------------------------------------------------------------------------
// Broken files: each must raise InputError naming the file and the line (or byte offset).

// A valid 4.1 file, one line per entry; line i+1 is kBase41[i].
const std::vector<std::string> kBase41 = {
    "$MeshFormat",          // 1
    "4.1 0 8",              // 2
    "$EndMeshFormat",       // 3
    "$PhysicalNames",       // 4
    "2",                    // 5
    "2 1 \"contact\"",      // 6
    "3 2 \"body\"",         // 7
    "$EndPhysicalNames",    // 8
    "$Entities",            // 9
    "0 0 1 1",              // 10
    "1 0 0 0 1 1 0 1 1 0",  // 11
    "1 0 0 0 1 1 1 1 2 0",  // 12
    "$EndEntities",         // 13
    "$Nodes",               // 14
    "1 4 1 4",              // 15
    "3 1 0 4",              // 16
    "1",                    // 17
    "2",                    // 18
    "3",                    // 19
    "4",                    // 20
    "0 0 0",                // 21
    "1 0 0",                // 22
    "0 1 0",                // 23
    "0 0 1",                // 24
    "$EndNodes",            // 25
    "$Elements",            // 26
    "2 2 1 2",              // 27
    "2 1 2 1",              // 28
    "1 1 3 2",              // 29
    "3 1 4 1",              // 30
    "2 1 2 3 4",            // 31
    "$EndElements",         // 32
};

std::string join(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}
// kBase41 with lines (1-based) replaced by texts (which may hold several lines or none).
std::string base41_with(const std::vector<std::pair<int, std::string>>& edits) {
  std::vector<std::string> lines = kBase41;
  for (const auto& [line, text] : edits) lines[static_cast<std::size_t>(line - 1)] = text;
  std::string out;
  for (const auto& l : lines)
    if (!l.empty()) out += l + "\n";
  return out;
}
std::string base41_with(int line, const std::string& text) { return base41_with({{line, text}}); }
std::string base41_first_lines(int n) { return join(std::vector<std::string>(kBase41.begin(), kBase41.begin() + n)); }

struct BrokenCase {
  std::string name;
  std::string contents;
  std::vector<std::string> expected;  // substrings of the message
};

TEST(MshReader, BaseFileIsValid) {
  const Mesh m = parse_msh(join(kBase41), "base.msh");
  EXPECT_EQ(m.nodes.size(), 4u);
  EXPECT_EQ(m.tets.size(), 1u);
  EXPECT_EQ(m.triangles_of_group("contact"), std::vector<int>({0}));
  EXPECT_EQ(m.tet_group, std::vector<int>({2}));
}

TEST(MshBroken, AsciiFilesNameFileAndLine) {
  const std::string base22 =
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"             // 1-3
      "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"  // 4-9
      "$Elements\n2\n1 2 2 1 1 1 2 3\n";                   // 10-12
  const std::vector<BrokenCase> cases = {
      {"version 3.0", base41_with(2, "3.0 0 8"), {"line 2", "3.0", "supported: 4.1, 2.2"}},
      {"version 4.0", base41_with(2, "4 0 8"), {"line 2", "supported: 4.1, 2.2"}},
      // A 4.1 ASCII body under a binary 2.2 header: the endianness marker is not there.
      {"binary 2.2 header on ASCII data",
       base41_with(2, "2.2 1 8"),
       {"byte offset 20", "corrupt binary header", "endianness marker"}},
      {"binary 2.2 data size 4",
       base41_with(2, "2.2 1 4"),
       {"line 2", "data size 4 is not supported in binary MSH 2.2"}},
      {"not msh", "hello world\n", {"line 1", "not a gmsh MSH file"}},
      {"bad coordinate", base41_with(22, "1 0 abc"), {"line 22", "'abc'", "coordinate"}},
      {"nan coordinate", base41_with(23, "0 nan 0"), {"line 23", "not a finite number"}},
      {"inf coordinate", base41_with(24, "0 0 -inf"), {"line 24", "not a finite number"}},
      {"huge coordinate", base41_with(23, "0 1e999 0"), {"line 23", "out of range"}},
      {"undefined node", base41_with(31, "2 1 2 3 99"), {"line 31", "element 2", "node 99", "$Nodes does not define"}},
      {"negative count", base41_with(15, "1 -4 1 4"), {"line 15", "non-negative", "'-4'"}},
      {"absurd count",
       base41_with(15, "1 4000000000000 1 4000000000000"),
       {"line 15", "4000000000000", "larger than the rest of the file"}},
      {"absurd element count",
       base41_with(30, "3 1 4 999999999999999"),
       {"line 30", "larger than the rest of the file"}},
      {"node count mismatch", base41_with(15, "1 5 1 5"), {"line 25", "announces 5 nodes"}},
      {"too few elements in block",
       base41_with({{27, "2 3 1 3"}, {30, "3 1 4 2"}}),
       {"line 32", "'$EndElements'", "before the count"}},
      {"element count mismatch", base41_with(27, "2 3 1 3"), {"line 32", "announces 3 elements"}},
      {"more elements than count", base41_with(27, "2 1 1 2"), {"line 30", "more elements"}},
      {"missing node in element", base41_with(31, "2 1 2 3"), {"line 31", "line ends"}},
      {"extra value in element", base41_with(29, "1 1 3 2 4"), {"line 29", "more values"}},
      {"bad integer", base41_with(29, "1x 1 3 2"), {"line 29", "'1x'"}},
      {"tet20",
       base41_with(30, "3 1 29 1"),
       {"line 30", "element type 29 (20-node tetrahedron) is not supported", "gmsh -order 1 or 2"}},
      {"tri10", base41_with(28, "2 1 21 1"), {"line 28", "element type 21 (10-node triangle)"}},
      {"hex", base41_with(30, "3 1 5 1"), {"line 30", "element type 5 (8-node hexahedron)"}},
      {"unknown type", base41_with(30, "3 1 77 1"), {"line 30", "element type 77"}},
      {"undefined entity", base41_with(28, "2 7 2 1"), {"line 28", "surface entity 7", "$Entities does not define"}},
      {"duplicate node tag", base41_with(18, "1"), {"line 14", "node tag 1 is defined twice"}},
      {"node tag zero", base41_with(17, "0"), {"line 17", "node tag 0"}},
      {"unterminated name", base41_with(6, "2 1 \"contact"), {"line 6", "closing quote"}},
      {"bad group dim", base41_with(6, "7 1 \"contact\""), {"line 6", "dimension 7"}},
      {"truncated", base41_first_lines(28), {"line 27", "element blocks 2 is larger", "truncated"}},
      {"truncated in a block",
       base41_first_lines(30) + "2 1 2",
       {"line 30", "is larger than the rest of the file", "truncated"}},
      {"no elements", base41_first_lines(25), {"no $Elements section"}},
      {"no nodes", base41_first_lines(13), {"no $Nodes section"}},
      {"elements before nodes",
       base41_first_lines(13) + "$Elements\n0 0 0 0\n$EndElements\n",
       {"line 14", "$Elements comes before $Nodes"}},
      {"unclosed section", join(kBase41) + "$Comments\nhello\n", {"line 33", "not closed by $EndComments"}},
      {"garbage between sections", base41_with(26, "garbage\n$Elements"), {"line 26", "expected a section header"}},
      {"missing section end", base41_with(25, ""), {"line 25", "expected $EndNodes, found '$Elements'"}},
      {"partitioned, empty",
       base41_with(13, "$EndEntities\n$PartitionedEntities\n$EndPartitionedEntities"),
       {"line 15", "the number of partitions"}},
      {"partitioned before $Entities",
       base41_with(9, "$PartitionedEntities\n1\n0\n0 0 0 0\n$EndPartitionedEntities\n$Entities"),
       {"line 9", "must come after $Entities"}},
      {"partitioned, truncated record",
       base41_with(13,
                   "$EndEntities\n$PartitionedEntities\n1\n0\n0 0 0 1\n7 3 1 1 1 0 0 0 1 1 1\n"
                   "$EndPartitionedEntities"),
       {"line 18", "physical tags"}},
      {"2.2 truncated", base22, {"line 13", "unexpected end of file"}},
      {"2.2 truncated mid-line", base22 + "2 4 2 1 1 1 2", {"line 13", "unexpected end of file"}},
      {"2.2 undefined node",
       base22 + "2 4 2 1 1 1 2 3 4\n$EndElements\n",
       {"line 13", "node 4", "$Nodes does not define"}},
      {"2.2 tet20",
       base22 + "2 29 2 1 1 1 2 3 1 2 3 1 2 3 1 1 2 3 1 2 3 1 2 3\n$EndElements\n",
       {"line 13", "element type 29 (20-node tetrahedron)", "gmsh -order 1 or 2"}},
      {"2.2 too many elements",
       base22 + "2 2 2 1 1 1 2 3\n3 2 2 1 1 1 2 3\n$EndElements\n",
       {"line 14", "expected $EndElements, found '3'", "more data"}},
      {"2.2 bad node line",
       std::string("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n2\n1 0 0 0\n2 0 0\n$EndNodes\n"),
       {"line 7", "z coordinate", "line ends"}},
  };
  TempDir dir;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const BrokenCase& c = cases[i];
    SCOPED_TRACE(c.name);
    const std::string path = dir.write("broken_" + std::to_string(i) + ".msh", c.contents);
    const std::string msg = input_error([&] { read_msh(path); });
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    for (const auto& e : c.expected) EXPECT_NE(msg.find(e), std::string::npos) << "'" << e << "' not in: " << msg;
  }
}

TEST(MshBroken, MissingFileOrDirectory) {
  const std::string missing = "/nonexistent/contact3d/mesh.msh";
  std::string msg = input_error([&] { read_msh(missing); });
  EXPECT_NE(msg.find(missing), std::string::npos) << msg;
  EXPECT_NE(msg.find("cannot open"), std::string::npos) << msg;
  TempDir dir;
  const std::string d = dir.file("");
  msg = input_error([&] { read_msh(d); });
  EXPECT_NE(msg.find(d), std::string::npos) << msg;
}

// A small file whose entity lists 100000 physical tags for a block of 3000 triangles would
// expand to 3e8 triangle entries: refused instead of allocated.
TEST(MshBroken, PhysicalTagAmplificationIsRefused) {
  std::string text =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
      "$Entities\n0 0 1 0\n1 0 0 0 1 1 0 100000";
  for (int i = 0; i < 100000; ++i) text += " 1";
  text +=
      " 0\n$EndEntities\n$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n"
      "$Elements\n1 3000 1 3000\n2 1 2 3000\n";  // the block header is line 20
  for (int i = 1; i <= 3000; ++i) text += std::to_string(i) + " 1 2 3\n";
  text += "$EndElements\n";
  const std::string msg = input_error([&] { parse_msh(text, "amplify.msh"); });
  EXPECT_NE(msg.find("amplify.msh, line 20:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("100000 physical tags"), std::string::npos) << msg;
}

// Byte position just after `marker` (which must occur in data).
std::size_t after(const std::string& data, const std::string& marker) {
  const std::size_t pos = data.find(marker);
  EXPECT_NE(pos, std::string::npos) << marker;
  return pos + marker.size();
}
template <class T>
void poke(std::string& data, std::size_t offset, T value) {
  ASSERT_LE(offset + sizeof(T), data.size());
  std::memcpy(data.data() + offset, &value, sizeof(T));
}
template <class T>
T peek(const std::string& data, std::size_t offset) {
  T v{};
  std::memcpy(&v, data.data() + offset, sizeof(T));
  return v;
}

TEST(MshBroken, BinaryFilesNameByteOffset) {
  const std::string good = slurp(kBinary41);
  const std::size_t nodes = after(good, "$Nodes\n");  // 4 x size_t header
  const std::size_t block = nodes + 32;               // dim, tag, parametric, count
  const std::size_t block_count = peek<std::uint64_t>(good, block + 12);
  const std::size_t first_coord = block + 20 + 8 * block_count;
  const std::size_t elements = after(good, "$Elements\n");
  const std::size_t first_element = elements + 32 + 20;  // its tag, then its nodes
  const std::size_t format_one = after(good, "4.1 1 8\n");

  struct Patch {
    std::string name;
    std::function<void(std::string&)> apply;
    std::size_t offset;
    std::string keyword;
  };
  const std::vector<Patch> patches = {
      {"absurd node count", [&](std::string& d) { poke<std::uint64_t>(d, nodes + 8, 1ull << 50); }, nodes + 8,
       "larger than the rest of the file"},
      {"absurd block count", [&](std::string& d) { poke<std::uint64_t>(d, block + 12, ~0ull); }, block + 12,
       "larger than the rest of the file"},
      {"nan coordinate", [&](std::string& d) { poke(d, first_coord, std::numeric_limits<double>::quiet_NaN()); },
       first_coord, "non-finite"},
      {"undefined node", [&](std::string& d) { poke<std::uint64_t>(d, first_element + 8, 9999); }, first_element + 8,
       "node 9999"},
      {"element type", [&](std::string& d) { poke<std::int32_t>(d, elements + 32 + 8, 29); }, elements + 32,
       "element type 29"},
      {"endianness", [&](std::string& d) { poke<std::int32_t>(d, format_one, 0x01000000); }, format_one, "big-endian"},
      {"truncated in a count", [&](std::string& d) { d.resize(nodes + 4); }, nodes, "unexpected end of file"},
      {"truncated in the nodes", [&](std::string& d) { d.resize(first_coord + 4); }, nodes,
       "larger than the rest of the file can hold (truncated"},
  };
  TempDir dir;
  for (const auto& p : patches) {
    SCOPED_TRACE(p.name);
    std::string data = good;
    p.apply(data);
    const std::string path = dir.write("bin.msh", data);
    const std::string msg = input_error([&] { read_msh(path); });
    EXPECT_NE(msg.find(path + ", byte offset " + std::to_string(p.offset) + ":"), std::string::npos) << msg;
    EXPECT_NE(msg.find(p.keyword), std::string::npos) << msg;
  }
}

// Every proper prefix of a valid file is an error (never a crash, hang or other exception).
TEST(MshBroken, EveryTruncationIsAnInputError) {
  for (const std::string& fixture : {kAscii41, kBinary41, kAscii22, kBinary22, kPartitioned41}) {
    SCOPED_TRACE(fixture);
    const std::string data = slurp(fixture);
    ASSERT_EQ(data.back(), '\n');
    for (std::size_t len = 0; len + 1 < data.size(); ++len) {
      try {
        parse_msh(std::string_view(data).substr(0, len), "prefix");
        ADD_FAILURE() << "prefix of " << len << " bytes was accepted";
        return;
      } catch (const InputError&) {}
    }
    EXPECT_EQ(parse_msh(std::string_view(data).substr(0, data.size() - 1), "p").tets.size(), 6u * 3 * kN * kN * kN);
  }
}

// Random corruption: the reader either accepts the file or raises InputError.
TEST(MshBroken, RandomCorruptionIsAcceptedOrInputError) {
  std::mt19937 rng(12345);
  const char alphabet[] = "0123456789 \n-.e$\"xnaif";
  for (const std::string& fixture : {kAscii41, kBinary41, kAscii22, kBinary22, kPartitioned41, kPartitionedGhosts41}) {
    SCOPED_TRACE(fixture);
    const std::string good = slurp(fixture);
    int accepted = 0;
    for (int iter = 0; iter < 1500; ++iter) {
      std::string data = good;
      const int edits = 1 + static_cast<int>(rng() % 3);
      for (int e = 0; e < edits && !data.empty(); ++e) {
        const std::size_t pos = rng() % data.size();
        switch (rng() % 4) {
          case 0:
            data[pos] = alphabet[rng() % (sizeof alphabet - 1)];
            break;
          case 1:
            data[pos] = static_cast<char>(rng() & 0xff);
            break;
          case 2:
            data.erase(pos, 1 + rng() % 8);
            break;
          default:
            data.insert(pos, 1, alphabet[rng() % (sizeof alphabet - 1)]);
            break;
        }
      }
      try {
        const Mesh m = parse_msh(data, "fuzz");
        ++accepted;
        for (const auto& t : m.tets)
          for (int v : t) ASSERT_TRUE(v >= 0 && static_cast<std::size_t>(v) < m.nodes.size());
        for (const auto& t : m.triangles)
          for (int v : t) ASSERT_TRUE(v >= 0 && static_cast<std::size_t>(v) < m.nodes.size());
      } catch (const InputError&) {}
    }
    RecordProperty(fs::path(fixture).filename().string() + "_accepted", accepted);
  }
}

// ---------------------------------------------------------------------------------------------
// MSH 2.2 binary

// Little-endian bytes of a value (the reader, like these tests, assumes a little-endian host).
template <class T>
std::string le(T v) {
  std::string s(sizeof(T), '\0');
  std::memcpy(s.data(), &v, sizeof(T));
  return s;
}
std::string le_ints(std::initializer_list<std::int32_t> values) {
  std::string s;
  for (std::int32_t v : values) s += le(v);
  return s;
}

// Nodes per element of the types gmsh writes in the fixtures.
std::size_t fixture_type_nodes(std::int32_t type) {
  switch (type) {
    case 15:
      return 1;
    case 1:
      return 2;
    case 2:
      return 3;
    case 4:
      return 4;
    default:
      ADD_FAILURE() << "element type " << type << " in a fixture";
      return 0;
  }
}

// Byte range [first, last) of the element blocks of a binary MSH 2.2 file: from after the
// count line of $Elements to the line break before $EndElements.
std::pair<std::size_t, std::size_t> element_blocks22(const std::string& data) {
  const std::size_t count = after(data, "$Elements\n");
  return {data.find('\n', count) + 1, data.rfind("\n$EndElements")};
}

// Offsets of the element block headers (element type, number of elements, number of tags).
std::vector<std::size_t> block_offsets22(const std::string& data) {
  auto [p, last] = element_blocks22(data);
  std::vector<std::size_t> out;
  while (p < last) {
    out.push_back(p);
    const auto type = peek<std::int32_t>(data, p);
    const auto n = static_cast<std::size_t>(peek<std::int32_t>(data, p + 4));
    const auto ntags = static_cast<std::size_t>(peek<std::int32_t>(data, p + 8));
    p += 12 + 4 * n * (1 + ntags + fixture_type_nodes(type));
  }
  EXPECT_EQ(p, last);
  return out;
}

// gmsh 4 writes one block per element; other writers put runs of elements of one type (and tag
// count) in one block. Rewrites a file that way.
std::string regroup_blocks22(const std::string& data) {
  const auto [first, last] = element_blocks22(data);
  std::string blocks, body;
  std::int32_t type = -1, ntags = -1, count = 0;
  const auto flush = [&] {
    if (count > 0) blocks += le_ints({type, count, ntags}) + body;
    body.clear();
    count = 0;
  };
  for (std::size_t b : block_offsets22(data)) {
    const auto t = peek<std::int32_t>(data, b);
    const auto n = peek<std::int32_t>(data, b + 4);
    const auto k = peek<std::int32_t>(data, b + 8);
    if (t != type || k != ntags) {
      flush();
      type = t;
      ntags = k;
    }
    body += data.substr(b + 12,
                        4 * static_cast<std::size_t>(n) * (1 + static_cast<std::size_t>(k) + fixture_type_nodes(t)));
    count += n;
  }
  flush();
  return data.substr(0, first) + blocks + data.substr(last);
}

// gmsh writes MSH 2.2 ASCII coordinates with printf("%.16g"), binary ones with all their bits:
// the mesh read from a binary file, its coordinates rounded that way.
Mesh rounded_as_msh22_ascii(Mesh m) {
  for (auto& x : m.nodes)
    for (int k = 0; k < 3; ++k) {
      char buf[40];
      std::snprintf(buf, sizeof buf, "%.16g", x[k]);
      x[k] = std::strtod(buf, nullptr);
    }
  return m;
}

TEST(MshReader, Gmsh22BinaryMatchesAscii) {
  const Mesh brick = read_msh(kBinary22);
  check_brick(brick, kN);
  expect_same_mesh(brick, read_msh(kAscii22));  // coordinates k/2, k/6: exact in both
  expect_same_mesh(brick, read_msh(kAscii41));
  for (const auto& [binary, ascii] : {std::pair{kBinary22, kAscii22}, std::pair{kHoledBinary22, kHoledAscii22},
                                      std::pair{kMultiBinary22, kMultiAscii22}}) {
    SCOPED_TRACE(binary);
    const Mesh b = read_msh(binary);
    EXPECT_FALSE(b.tets.empty());
    EXPECT_FALSE(b.triangles.empty());
    expect_same_mesh(rounded_as_msh22_ascii(b), read_msh(ascii));
  }
  const Mesh holed = read_msh(kHoledBinary22);
  EXPECT_EQ(holed.nodes.size(), 104u);
  const char* names[] = {"clamped", "load_top", "load_end", "contact", "free", "body"};
  ASSERT_EQ(holed.groups.size(), 6u) << holed.describe_groups();
  for (int i = 0; i < 6; ++i) EXPECT_EQ(holed.groups[i].name, names[i]);
  EXPECT_FALSE(holed.triangles_of_group("contact").empty());
}

// meshes/fixtures/multigroup.geo: a cube whose boundary faces and volume are each in two
// physical groups, a physical point and curve (elements of type 15 and 1, skipped), and an
// unnamed physical surface 42.
TEST(MshReader, Gmsh22BinarySeveralGroupsPerElement) {
  const Mesh m = read_msh(kMultiBinary22);
  EXPECT_EQ(m.nodes.size(), 14u);
  // gmsh writes each tetrahedron for "body" (43) then "body_again" (44): stored once, in both groups.
  EXPECT_EQ(m.tets.size(), 24u);
  for (int g : m.tet_group) EXPECT_EQ(g, 43);
  EXPECT_EQ(m.tets_of_group(44).size(), 24u);
  EXPECT_EQ(m.tets_of_group(43).size(), 24u);
  double volume = 0;
  for (const auto& t : m.tets) volume += std::abs(tet_volume(m, t));
  EXPECT_NEAR(volume, 1.0, 1e-12);
  // Triangles are stored once per group.
  EXPECT_EQ(m.triangles_of_group("contact").size(), 4u);
  EXPECT_EQ(m.triangles_of_group("also_contact").size(), 4u);
  EXPECT_EQ(m.triangles_of_group("sides").size(), 16u);
  EXPECT_EQ(m.triangles_of_group("").size(), 4u);
  EXPECT_EQ(m.triangles.size(), 28u);
  // The named groups in file order, then the unnamed one.
  ASSERT_EQ(m.groups.size(), 8u) << m.describe_groups();
  EXPECT_EQ(m.groups[0].name, "corner");
  EXPECT_EQ(m.groups[0].dim, 0);
  EXPECT_EQ(m.groups[1].name, "edge");
  EXPECT_EQ(m.groups[1].dim, 1);
  EXPECT_EQ(m.groups[6].name, "body_again");
  EXPECT_EQ(m.groups[6].tag, 44);
  EXPECT_EQ(m.groups[7].dim, 2);
  EXPECT_EQ(m.groups[7].tag, 42);
  EXPECT_EQ(m.groups[7].name, "");
}

// Blocks holding many elements (as written by gmsh 2 and other writers) read the same.
TEST(MshReader, Msh22BinaryBlocksOfSeveralElements) {
  for (const std::string& fixture : {kBinary22, kHoledBinary22, kMultiBinary22}) {
    SCOPED_TRACE(fixture);
    const std::string data = slurp(fixture);
    const std::string grouped = regroup_blocks22(data);
    EXPECT_GT(block_offsets22(data).size(), 50u);
    EXPECT_LE(block_offsets22(grouped).size(), 4u);
    expect_same_mesh(parse_msh(grouped, "grouped.msh"), read_msh(fixture));
  }
}

// Hand-built: sparse node tags, 4 tags per element (gmsh's partition tags), an empty block, a
// tetrahedron written for two groups, count lines ending in "\r\n"; same Mesh as the ASCII text.
TEST(MshReader, Msh22BinaryHandBuiltMatchesAscii) {
  const std::string ascii =
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
      "$PhysicalNames\n2\n2 4 \"contact\"\n3 6 \"body\"\n$EndPhysicalNames\n"
      "$Nodes\n5\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n1000000007 1 1 1\n$EndNodes\n"
      "$Elements\n7\n"
      "1 15 2 0 1 10\n"
      "2 1 4 0 3 1 2 10 20\n"
      "3 2 4 4 1 1 2 10 20 30\n"
      "4 2 4 0 1 1 2 10 30 40\n"
      "5 4 2 6 1 10 20 30 40\n"
      "6 4 2 9 1 10 20 30 40\n"
      "7 4 2 6 1 20 30 40 1000000007\n"
      "$EndElements\n";
  std::string bin = "$MeshFormat\n2.2 1 8\n" + le<std::int32_t>(1) +
                    "\n$EndMeshFormat\n"
                    "$PhysicalNames\n2\n2 4 \"contact\"\n3 6 \"body\"\n$EndPhysicalNames\n"
                    "$Nodes\r\n5\r\n";
  const std::pair<std::int32_t, Eigen::Vector3d> nodes[] = {
      {10, {0, 0, 0}}, {20, {1, 0, 0}}, {30, {0, 1, 0}}, {40, {0, 0, 1}}, {1000000007, {1, 1, 1}}};
  for (const auto& [tag, x] : nodes) bin += le(tag) + le(x.x()) + le(x.y()) + le(x.z());
  bin += "\n$EndNodes\n$Elements\r\n7\r\n";
  bin += le_ints({15, 1, 2, /**/ 1, 0, 1, 10});
  bin += le_ints({1, 1, 4, /**/ 2, 0, 3, 1, 2, 10, 20});
  bin += le_ints({2, 0, 2});  // an empty block
  bin += le_ints({2, 2, 4, /**/ 3, 4, 1, 1, 2, 10, 20, 30, /**/ 4, 0, 1, 1, 2, 10, 30, 40});
  bin += le_ints({4,      3, 2, /**/ 5, 6,  1,  10,        20, 30, 40, /**/ 6, 9, 1, 10, 20, 30, 40,
                  /**/ 7, 6, 1, 20,     30, 40, 1000000007});
  bin += "\n$EndElements\n";
  const Mesh m = parse_msh(bin, "hand.msh");
  expect_same_mesh(m, parse_msh(ascii, "hand_ascii.msh"));
  EXPECT_EQ(m.node_tags, std::vector<std::size_t>({10, 20, 30, 40, 1000000007}));
  EXPECT_EQ(m.tets, std::vector<Tet>({{0, 1, 2, 3}, {1, 2, 3, 4}}));
  EXPECT_EQ(m.tet_tags, std::vector<std::size_t>({5, 7}));
  EXPECT_EQ(m.tet_group, std::vector<int>({6, 6}));
  EXPECT_EQ(m.triangle_tags, std::vector<std::size_t>({3, 4}));
  EXPECT_EQ(m.triangle_group, std::vector<int>({4, 0}));
  ASSERT_EQ(m.groups.size(), 3u);
  EXPECT_EQ(m.groups[2].dim, 3);
  EXPECT_EQ(m.groups[2].tag, 9);
}

// Broken binary 2.2 files built from the brick fixture: each raises InputError naming the file,
// the byte offset of the problem and the problem.
TEST(MshBroken, Binary22FilesNameByteOffset) {
  const std::string good = slurp(kBinary22);
  const std::size_t format_one = after(good, "2.2 1 8\n");
  const std::size_t nodes_header = good.find("$Nodes\n");
  const std::size_t node_count = after(good, "$Nodes\n");
  const std::size_t first_node = after(good, "$Nodes\n63\n");  // 28 bytes per node
  const std::size_t element_count = after(good, "$Elements\n");
  const std::vector<std::size_t> blocks = block_offsets22(good);
  ASSERT_EQ(blocks.size(), 256u);  // gmsh 4 writes one block per element
  const std::size_t first_tet_block = blocks[112];
  ASSERT_EQ(peek<std::int32_t>(good, first_tet_block), 4);
  ASSERT_EQ(peek<std::int32_t>(good, first_tet_block + 12), 113);
  const std::size_t last_block = blocks.back();
  ASSERT_EQ(last_block + 12 + 28, element_blocks22(good).second);
  const std::size_t blocks_end = element_blocks22(good).second;
  const auto replace = [](std::string& d, const std::string& from, const std::string& to) {
    const std::size_t pos = d.find(from);
    ASSERT_NE(pos, std::string::npos) << from;
    d.replace(pos, from.size(), to);
  };

  struct Patch {
    std::string name;
    std::function<std::size_t(std::string&)> apply;  // returns the offset the error must name
    std::vector<std::string> keywords;
  };
  using D = std::string&;
  const std::vector<Patch> patches = {
      // Header
      {"flipped endianness marker",
       [&](D d) {
         poke<std::int32_t>(d, format_one, 0x01000000);
         return format_one;
       },
       {"big-endian"}},
      {"corrupt endianness marker",
       [&](D d) {
         poke<std::int32_t>(d, format_one, 7);
         return format_one;
       },
       {"corrupt binary header", "endianness marker is 7"}},
      // Truncations
      {"truncated in the endianness marker",
       [&](D d) {
         d.resize(format_one + 2);
         return format_one;
       },
       {"unexpected end of file in binary data", "endianness marker"}},
      {"truncated in the nodes",
       [&](D d) {
         d.resize(first_node + 10 * 28 + 5);
         return node_count;
       },
       {"the number of nodes 63 is larger than the rest of the file can hold (truncated"}},
      {"truncated before the element blocks",
       [&](D d) {
         d.resize(element_count + 100);
         return element_count;
       },
       {"the number of elements 256 is larger than the rest of the file can hold (truncated"}},
      {"truncated in a block header",
       [&](D d) {
         d.resize(last_block + 6);
         return last_block + 4;
       },
       {"unexpected end of file in binary data", "the number of elements in the block"}},
      // The last block: a 12-byte header, then one tetrahedron of 28 bytes.
      {"truncated in an element",
       [&](D d) {
         d.resize(blocks_end - 20);
         return last_block + 4;
       },
       {"the number of elements in the block 1 is larger than the rest of the file can hold"}},
      {"truncated before $EndElements",
       [&](D d) {
         d.resize(blocks_end);
         return blocks_end;
       },
       {"unexpected end of file; expected $EndElements"}},
      // Counts
      {"huge node count",
       [&](D d) {
         replace(d, "$Nodes\n63\n", "$Nodes\n4000000000000\n");
         return node_count;
       },
       {"the number of nodes 4000000000000 is larger than the rest of the file can hold"}},
      {"node count too large",
       [&](D d) {
         replace(d, "$Nodes\n63\n", "$Nodes\n64\n");
         return first_node + 63 * 28;
       },
       {"the $Nodes header announces 64 nodes but the section ends after 63"}},
      {"node count too small",
       [&](D d) {
         replace(d, "$Nodes\n63\n", "$Nodes\n62\n");
         return first_node + 62 * 28;
       },
       {"expected $EndNodes", "more data than the counts"}},
      {"huge element count",
       [&](D d) {
         replace(d, "$Elements\n256\n", "$Elements\n4000000000000\n");
         return element_count;
       },
       {"the number of elements 4000000000000 is larger than the rest of the file can hold"}},
      {"element count too large",
       [&](D d) {
         replace(d, "$Elements\n256\n", "$Elements\n257\n");
         return blocks_end;
       },
       {"the $Elements header announces 257 elements but its blocks hold 256"}},
      {"element count too small",
       [&](D d) {
         replace(d, "$Elements\n256\n", "$Elements\n255\n");
         return last_block;
       },
       {"expected $EndElements", "more data than the counts"}},
      {"huge block count",
       [&](D d) {
         poke<std::int32_t>(d, blocks[0] + 4, 0x7fffffff);
         return blocks[0] + 4;
       },
       {"the number of elements in the block 2147483647 is larger than the rest of the file"}},
      {"block count beyond the header's",
       [&](D d) {
         replace(d, "$Elements\n256\n", "$Elements\n1\n");  // 2 bytes shorter
         poke<std::int32_t>(d, blocks[0] - 2 + 4, 2);
         return blocks[0] - 2 + 4;
       },
       {"the element blocks hold more elements than the 1 announced"}},
      {"negative block count",
       [&](D d) {
         poke<std::int32_t>(d, blocks[0] + 4, -1);
         return blocks[0] + 4;
       },
       {"the number of elements in the block is negative (-1)"}},
      {"huge tag count",
       [&](D d) {
         poke<std::int32_t>(d, blocks[0] + 8, 0x7fffffff);
         return blocks[0] + 8;
       },
       {"the number of tags per element 2147483647 is larger than the rest of the file"}},
      {"negative tag count",
       [&](D d) {
         poke<std::int32_t>(d, blocks[0] + 8, -2);
         return blocks[0] + 8;
       },
       {"the number of tags per element is negative (-2)"}},
      // Element types
      {"20-node tetrahedron block",
       [&](D d) {
         poke<std::int32_t>(d, first_tet_block, 29);
         return first_tet_block;
       },
       {"element type 29 (20-node tetrahedron) is not supported", "gmsh -order 1 or 2"}},
      {"hexahedron block",
       [&](D d) {
         poke<std::int32_t>(d, first_tet_block, 5);
         return first_tet_block;
       },
       {"element type 5 (8-node hexahedron) is not supported"}},
      {"unknown element type",
       [&](D d) {
         poke<std::int32_t>(d, blocks[0], 77);
         return blocks[0];
       },
       {"element type 77 (unknown to this reader) is not supported"}},
      // Element records
      {"undefined node",
       [&](D d) {
         poke<std::int32_t>(d, blocks[0] + 24, 9999);
         return blocks[0] + 24;
       },
       {"element 1 refers to node 9999, which $Nodes does not define", "(in $Elements)"}},
      {"negative node",
       [&](D d) {
         poke<std::int32_t>(d, blocks[0] + 24, -3);
         return blocks[0] + 24;
       },
       {"element 1 refers to node -3"}},
      {"node out of range in a tetrahedron",
       [&](D d) {
         poke<std::int32_t>(d, first_tet_block + 36, 64);
         return first_tet_block + 36;
       },
       {"element 113 refers to node 64"}},
      {"element tag 0",
       [&](D d) {
         poke<std::int32_t>(d, blocks[0] + 12, 0);
         return blocks[0] + 12;
       },
       {"element tag 0 is not valid"}},
      // Nodes
      {"duplicate node tag",
       [&](D d) {
         poke<std::int32_t>(d, first_node + 28, 1);
         return nodes_header;
       },
       {"node tag 1 is defined twice"}},
      {"node tag 0",
       [&](D d) {
         poke<std::int32_t>(d, first_node, 0);
         return first_node;
       },
       {"node tag 0 is not valid"}},
      {"negative node tag",
       [&](D d) {
         poke<std::int32_t>(d, first_node + 56, -7);
         return first_node + 56;
       },
       {"node tag -7 is not valid"}},
      {"nan coordinate",
       [&](D d) {
         poke(d, first_node + 12, std::numeric_limits<double>::quiet_NaN());
         return first_node + 4;
       },
       {"node 1 has a non-finite coordinate", "(in $Nodes)"}},
  };
  TempDir dir;
  for (const auto& p : patches) {
    SCOPED_TRACE(p.name);
    std::string data = good;
    const std::size_t offset = p.apply(data);
    const std::string path = dir.write("bin22.msh", data);
    const std::string msg = input_error([&] { read_msh(path); });
    EXPECT_NE(msg.find(path + ", byte offset " + std::to_string(offset) + ":"), std::string::npos) << msg;
    for (const auto& k : p.keywords) EXPECT_NE(msg.find(k), std::string::npos) << "'" << k << "' not in: " << msg;
  }
}

// Every prefix and every single overwritten byte or int of the binary 2.2 fixtures gives a Mesh
// with indices in range or an InputError (never a crash, hang or other exception).
TEST(MshBroken, Binary22PrefixesAndOverwritesAreAcceptedOrInputError) {
  // Whether the data is accepted; fails the test if the Mesh has an index out of range.
  const auto check = [](const std::string& data) -> bool {
    try {
      const Mesh m = parse_msh(data, "fuzz");
      const auto in_range = [&](int v) { return v >= 0 && static_cast<std::size_t>(v) < m.nodes.size(); };
      for (const auto& t : m.tets)
        for (int v : t) EXPECT_TRUE(in_range(v));
      for (const auto& t : m.triangles)
        for (int v : t) EXPECT_TRUE(in_range(v));
      return true;
    } catch (const InputError&) { return false; }
  };
  for (const std::string& fixture : {kMultiBinary22, kHoledBinary22}) {
    SCOPED_TRACE(fixture);
    const std::string good = slurp(fixture);
    for (std::size_t len = 0; len + 1 < good.size(); ++len)
      ASSERT_FALSE(check(good.substr(0, len))) << "prefix of " << len << " bytes was accepted";
  }
  const std::string good = slurp(kMultiBinary22);
  for (std::size_t pos = 0; pos < good.size(); ++pos) {
    for (const char c : {'\0', '\xff', '\x7f', '\n', ' ', '$', '1'}) {
      std::string data = good;
      data[pos] = c;
      check(data);
    }
  }
  const std::size_t nodes = after(good, "$Nodes\n");
  for (std::size_t pos = nodes; pos + 4 <= good.size(); pos += 4) {
    for (const std::int32_t v : {0, -1, 1, 14, 15, 0x7fffffff, std::numeric_limits<std::int32_t>::min()}) {
      std::string data = good;
      poke(data, pos, v);
      check(data);
    }
  }
}

}  // namespace
}  // namespace contact3d
