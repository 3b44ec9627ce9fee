// The Medit reader (FreeFEM's savemesh): the FreeFEM-made fixtures in ASCII and binary give the
// same mesh, labels become groups named by number, and every kind of broken file is an
// InputError naming the file and where (line or byte offset) and the section.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>

#include "base/errors.hpp"
#include "mesh/medit_reader.hpp"
#include "mesh/read_mesh.hpp"

namespace contact3d {
namespace {

std::string fixture(const std::string& name) { return std::string(CONTACT3D_SOURCE_DIR) + "/meshes/fixtures/" + name; }

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const char* kTwoTets = R"(MeshVersionFormatted 2
# a comment
Dimension 3
Vertices
5
0 0 0 1
1 0 0 1
0 1 0 1
0 0 1 1
0 0 -1 1
Tetrahedra
2
1 2 3 4 7
1 3 2 5 8
Triangles
1
1 2 3 5
End
)";

std::string error_of(const std::string& text) {
  try {
    parse_medit(text, "bad.mesh");
  } catch (const InputError& e) { return e.what(); }
  return "";
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(MeditReader, ReadsVerticesElementsAndLabels) {
  const Mesh m = parse_medit(kTwoTets, "two.mesh");
  ASSERT_EQ(m.nodes.size(), 5u);
  ASSERT_EQ(m.tets.size(), 2u);
  EXPECT_EQ(m.tets[1], (std::array<int, 4>{0, 2, 1, 4}));
  EXPECT_EQ(m.tet_group[1], 8);
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.triangle_group[0], 5);
  ASSERT_NE(m.find_group("5", 2), nullptr);
  ASSERT_NE(m.find_group("7", 3), nullptr);
  EXPECT_EQ(m.find_group("5", 3), nullptr);
  EXPECT_EQ(m.triangles_of_group("5").size(), 1u);
}

TEST(MeditReader, FreeFemAsciiAndBinaryAgree) {
  const Mesh a = read_mesh_file(fixture("freefem_cube2.mesh"));
  const Mesh b = read_mesh_file(fixture("freefem_cube2.meshb"));
  ASSERT_EQ(a.nodes.size(), 27u);
  ASSERT_EQ(a.tets.size(), 48u);
  ASSERT_EQ(a.triangles.size(), 48u);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (std::size_t v = 0; v < a.nodes.size(); ++v) EXPECT_EQ(a.nodes[v], b.nodes[v]);
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.triangle_group, b.triangle_group);
  for (int label = 1; label <= 6; ++label) EXPECT_EQ(a.triangles_of_group(std::to_string(label)).size(), 8u);
  // z = 0 is label 5 in FreeFEM's cube.
  for (int t : a.triangles_of_group("5"))
    for (int v : a.triangles[t]) EXPECT_EQ(a.nodes[v].z(), 0.0);
}

TEST(MeditReader, BrokenFilesNameWhereAndWhat) {
  struct Case {
    std::string text;
    std::vector<std::string> facts;
  };
  const std::string t = kTwoTets;
  const std::vector<Case> cases = {
      {replaced(t, "Dimension 3", "Dimension 2"), {"bad.mesh", "line 3", "dimension 2", "3-D"}},
      {replaced(t, "Dimension 3\n", ""), {"Vertices before 'Dimension 3'"}},
      {replaced(t, "Vertices\n5", "Vertices\n500000"), {"line", "Vertices", "does not fit"}},
      {replaced(t, "0 1 0 1", "0 one 0 1"), {"line 8", "Vertices", "'one'"}},
      {replaced(t, "0 0 1 1", "0 0 nan 1"), {"line 9", "not finite"}},
      {replaced(t, "1 3 2 5 8", "1 3 2 9 8"), {"Tetrahedra", "entry 2", "vertex 9", "1 to 5"}},
      {replaced(t, "1 2 3 5\n", "1 2 0 5\n"), {"Triangles", "vertex 0"}},
      {replaced(t, "Triangles", "Quadrilaterals\n1\n1 2 3 4 0\nTriangles"),
       {"Quadrilaterals", "quadrilaterals", "tetrahedra and triangles only"}},
      {replaced(t, "Triangles", "QuadrilateralsQ2\n1\n1 2 3 4 1 2 3 4 1 0\nTriangles"),
       {"second-order quadrilaterals"}},
      {replaced(t, "Triangles", "Hexahedra\n1\n1 2 3 4 5 1 2 3 0\nTriangles"), {"hexahedra"}},
      {replaced(t, "Triangles", "Blobs\n1\nTriangles"), {"unknown keyword 'Blobs'", "line"}},
      {replaced(t, "End\n", ""), {"without 'End'"}},
      {replaced(replaced(t, "Tetrahedra\n2\n1 2 3 4 7\n1 3 2 5 8\n", ""), "Triangles", "Triangles"), {"no Tetrahedra"}},
      {t.substr(0, t.find("Tetrahedra") + 14), {"Tetrahedra", "does not fit"}},
      {t.substr(0, t.find("1 3 2 5 8")), {"Tetrahedra", "ends inside the section"}},
      {"hello world\n", {"unknown keyword 'hello'"}},
      {"", {"no 'Dimension 3'"}},
  };
  for (const auto& c : cases) {
    const std::string msg = error_of(c.text);
    ASSERT_FALSE(msg.empty()) << c.text;
    for (const auto& f : c.facts) EXPECT_NE(msg.find(f), std::string::npos) << "'" << f << "' not in: " << msg;
  }
}

// Second order (gmsh -order 2 -format mesh): a TetrahedraP2 entry lists 4 corners then 6 mid-edge
// vertices, a TrianglesP2 entry 3 then 3; the corners are kept, the mid-edge vertices dropped and
// the others renumbered, their positions kept as node tags. EdgesP2 are skipped.
TEST(MeditReader, SecondOrderElementsAreReadByTheirCorners) {
  const std::string text =
      "MeshVersionFormatted 2\nDimension 3\nVertices\n10\n"
      "0 0 0 0\n0.5 0 0 0\n1 0 0 0\n0 0.5 0 0\n0 1 0 0\n0 0 0.5 0\n0 0 1 0\n0.5 0.5 0 0\n0.5 0 0.5 0\n"
      "0 0.5 0.5 0\n"
      "EdgesP2\n1\n1 3 2 4\n"
      "TrianglesP2\n1\n1 3 5 2 8 4 5\n"
      "TetrahedraP2\n1\n1 3 5 7 2 8 4 6 10 9 1\nEnd\n";
  const Mesh m = parse_medit(text, "p2.mesh");
  EXPECT_TRUE(m.read_by_corner_nodes);
  ASSERT_EQ(m.nodes.size(), 4u);
  EXPECT_EQ(m.node_tags, std::vector<std::size_t>({1, 3, 5, 7}));
  EXPECT_EQ(m.nodes[2], Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(m.tets, (std::vector<std::array<int, 4>>{{0, 1, 2, 3}}));
  EXPECT_EQ(m.triangles, (std::vector<std::array<int, 3>>{{0, 1, 2}}));
  EXPECT_EQ(m.triangles_of_group("5").size(), 1u);
  EXPECT_FALSE(parse_medit(kTwoTets, "p1.mesh").read_by_corner_nodes);
}

// A binary Medit file (.meshb, version 2: 32-bit integers, 64-bit reals) written keyword by
// keyword: code, position of the next keyword, data; the header and the dimension first.
struct MeditBinary {
  std::string data;
  MeditBinary() {
    put_int(1);  // endianness
    put_int(2);  // version
    keyword(3, [&] { put_int(3); });
  }
  void put_int(std::int32_t v) { data.append(reinterpret_cast<const char*>(&v), 4); }
  void put_real(double v) { data.append(reinterpret_cast<const char*>(&v), 8); }
  void keyword(std::int32_t code, const std::function<void()>& body) {
    put_int(code);
    const std::size_t next = data.size();
    put_int(0);
    body();
    const std::int32_t end = static_cast<std::int32_t>(data.size());
    std::memcpy(data.data() + next, &end, 4);
  }
  // The End keyword; the file's bytes.
  const std::string& finish() {
    put_int(54);
    put_int(0);
    return data;
  }
};

// The same in binary.
TEST(MeditReader, SecondOrderElementsAreReadByTheirCornersInBinary) {
  MeditBinary b;
  const auto put_int = [&](std::int32_t v) { b.put_int(v); };
  const auto put_real = [&](double v) { b.put_real(v); };
  const auto keyword = [&](std::int32_t code, const std::function<void()>& body) { b.keyword(code, body); };
  const double xyz[10][3] = {{0, 0, 0},   {0.5, 0, 0}, {1, 0, 0},     {0, 0.5, 0},   {0, 1, 0},
                             {0, 0, 0.5}, {0, 0, 1},   {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  keyword(4, [&] {
    put_int(10);
    for (const auto& x : xyz) {
      for (double c : x) put_real(c);
      put_int(0);
    }
  });
  keyword(24, [&] {  // TrianglesP2
    put_int(1);
    for (std::int32_t v : {1, 3, 5, 2, 8, 4, 5}) put_int(v);
  });
  keyword(30, [&] {  // TetrahedraP2
    put_int(1);
    for (std::int32_t v : {1, 3, 5, 7, 2, 8, 4, 6, 10, 9, 1}) put_int(v);
  });
  const Mesh m = parse_medit(b.finish(), "p2.meshb");
  EXPECT_TRUE(m.read_by_corner_nodes);
  ASSERT_EQ(m.nodes.size(), 4u);
  EXPECT_EQ(m.nodes[3], Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(m.tets, (std::vector<std::array<int, 4>>{{0, 1, 2, 3}}));
  EXPECT_EQ(m.triangles, (std::vector<std::array<int, 3>>{{0, 1, 2}}));
}

TEST(MeditReader, EdgesCornersAndRequiredEntitiesAreSkipped) {
  const std::string t = replaced(kTwoTets, "Triangles", "Edges\n1\n1 2 3\nCorners\n1\n1\nRidges\n1\n1\nTriangles");
  const Mesh m = parse_medit(t, "extra.mesh");
  EXPECT_EQ(m.tets.size(), 2u);
  EXPECT_EQ(m.triangles.size(), 1u);
}

// MMG writes the tetrahedra it was told to keep as RequiredTetrahedra (binary code 12): skipped.
TEST(MeditReader, RequiredTetrahedraAreSkipped) {
  const Mesh m = parse_medit(replaced(kTwoTets, "End", "RequiredTetrahedra\n2\n1\n2\nEnd"), "mmg.mesh");
  EXPECT_EQ(m.tets.size(), 2u);
}

// A file named .meshb that is not binary, and a binary file read as text: each refused in one
// readable line, the text's bytes quoted only as printable characters and only its first 40.
TEST(MeditReader, GarbageIsRefusedReadably) {
  std::string garbage = "\x1e\xda\x9d\x10\xab*\x1e\xf7\xd1s\xc3&\xd4";
  for (int k = 0; k < 10; ++k) garbage += garbage;
  std::string what;
  try {
    parse_medit(garbage, "random.meshb");
  } catch (const InputError& e) { what = e.what(); }
  EXPECT_NE(what.find("random.meshb: not a Medit binary file"), std::string::npos) << what;
  what = error_of(garbage);
  EXPECT_NE(what.find("unknown keyword '\\x1e"), std::string::npos) << what;
  EXPECT_LT(what.size(), 400u) << what;
  for (const char c : what) EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20 && c != '\n') << what;
}

// What MMG and other remeshers add to a mesh: normals and tangents with their links to vertices
// and triangles, in ASCII (reals and integers counted per entry) and in binary (skipped by the
// keyword's next-position pointer).
TEST(MeditReader, NormalsAndTangentsAreSkipped) {
  const std::string t = replaced(kTwoTets, "End",
                                 "Normals\n2\n0 0 -1\n0.6 0.8 0\nNormalAtVertices\n1\n1 1\n"
                                 "NormalAtTriangleVertices\n1\n1 2 2\nTangents\n1\n1 0 0\n"
                                 "TangentAtVertices\n1\n2 1\nTangentAtEdgeVertices\n1\n1 1 1\n"
                                 "RequiredQuadrilaterals\n0\nEnd");
  const Mesh m = parse_medit(t, "remeshed.mesh");
  EXPECT_EQ(m.tets.size(), 2u);
  EXPECT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.nodes[4], Eigen::Vector3d(0, 0, -1));
  // One real too few in Normals: the next keyword is read as a number, and the error says where.
  const std::string short_normal = replaced(t, "0.6 0.8 0\n", "0.6 0.8\n");
  EXPECT_NE(error_of(short_normal).find("bad.mesh"), std::string::npos);
}

TEST(MeditReader, NormalsAndTangentsAreSkippedInBinary) {
  MeditBinary b;
  const auto put_int = [&](std::int32_t v) { b.put_int(v); };
  const auto put_real = [&](double v) { b.put_real(v); };
  const auto keyword = [&](std::int32_t code, const std::function<void()>& body) { b.keyword(code, body); };
  keyword(4, [&] {
    put_int(4);
    for (const auto& x : {std::array<double, 3>{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}) {
      for (double c : x) put_real(c);
      put_int(0);
    }
  });
  keyword(60, [&] {  // Normals
    put_int(1);
    for (double c : {0.0, 0.0, -1.0}) put_real(c);
  });
  keyword(20, [&] {  // NormalAtVertices
    put_int(1);
    put_int(1);
    put_int(1);
  });
  keyword(59, [&] {  // Tangents
    put_int(1);
    for (double c : {1.0, 0.0, 0.0}) put_real(c);
  });
  keyword(61, [&] {  // TangentAtVertices
    put_int(1);
    put_int(2);
    put_int(1);
  });
  keyword(8, [&] {  // Tetrahedra
    put_int(1);
    for (std::int32_t v : {1, 2, 3, 4, 1}) put_int(v);
  });
  const Mesh m = parse_medit(b.finish(), "remeshed.meshb");
  EXPECT_EQ(m.nodes.size(), 4u);
  EXPECT_EQ(m.tets.size(), 1u);
}

TEST(MeditReader, BinaryPrefixesAndOverwritesNeverCrash) {
  const std::string data = slurp(fixture("freefem_cube2.meshb"));
  ASSERT_GT(data.size(), 100u);
  int errors = 0;
  for (std::size_t n = 0; n < data.size(); n += 7) {  // every 7th prefix: truncated files
    try {
      parse_medit(data.substr(0, n), "cut.meshb");
    } catch (const InputError& e) {
      ++errors;
      EXPECT_NE(std::string(e.what()).find("cut.meshb"), std::string::npos);
    }
  }
  EXPECT_GT(errors, 0);
  for (std::size_t at = 0; at + 4 <= 200; at += 4) {  // the header and the first keywords overwritten
    for (std::uint32_t value : {0u, 0xffffffffu, 0x7fffffffu, 3u, 54u}) {
      std::string bad = data;
      std::memcpy(bad.data() + at, &value, 4);
      try {
        parse_medit(bad, "over.meshb");
      } catch (const InputError&) {}
    }
  }
}

TEST(MeditReader, DispatchByExtension) {
  EXPECT_TRUE(is_medit_path("a/b.mesh"));
  EXPECT_TRUE(is_medit_path("x.meshb"));
  EXPECT_FALSE(is_medit_path("x.msh"));
  EXPECT_FALSE(is_medit_path("mesh"));
  EXPECT_TRUE(is_medit_path("FF.MESH"));
}

// The reader is chosen by the file's first bytes where they tell: a gmsh file named .mesh and a Medit
// file named .MESH or .msh are read by their own readers (a helper's were refused by the other one).
TEST(MeditReader, DispatchByContent) {
  const std::string dir = ::testing::TempDir();
  auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir + name, std::ios::binary) << bytes;
    return dir + name;
  };
  EXPECT_FALSE(is_medit_file(write("gmsh_named.mesh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n")));
  EXPECT_TRUE(is_medit_file(write("medit_named.msh", "MeshVersionFormatted 2\nDimension 3\n")));
  EXPECT_TRUE(is_medit_file(write("commented.msh", "# FreeFEM\nMeshVersionFormatted 1\n")));
  EXPECT_TRUE(is_medit_file(write("binary.dat", std::string("\x01\x00\x00\x00\x02\x00\x00\x00", 8))));
  EXPECT_TRUE(is_medit_file(write("UPPER.MESH", "\n")));  // undecided: the name
  EXPECT_FALSE(is_medit_file(write("other.msh", "\n")));
  EXPECT_FALSE(is_medit_file(dir + "missing.msh"));  // unreadable: the name's reader says why
}

}  // namespace
}  // namespace contact3d
