// The Medit reader (FreeFEM's savemesh): the FreeFEM-made fixtures in ASCII and binary give the
// same mesh, labels become groups named by number, and every kind of broken file is an
// InputError naming the file and where (line or byte offset) and the section.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
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
      {replaced(t, "Triangles", "Quadrilaterals\n1\n1 2 3 4 0\nTriangles"), {"Quadrilaterals", "quadrilaterals", "P1"}},
      {replaced(t, "Triangles", "TetrahedraP2\n1\n1 2 3 4 1 2 3 4 1 2 0\nTriangles"), {"second-order"}},
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

TEST(MeditReader, EdgesCornersAndRequiredEntitiesAreSkipped) {
  const std::string t = replaced(kTwoTets, "Triangles", "Edges\n1\n1 2 3\nCorners\n1\n1\nRidges\n1\n1\nTriangles");
  const Mesh m = parse_medit(t, "extra.mesh");
  EXPECT_EQ(m.tets.size(), 2u);
  EXPECT_EQ(m.triangles.size(), 1u);
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
}

}  // namespace
}  // namespace contact3d
