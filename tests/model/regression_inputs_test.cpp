// Inputs that once crashed or hung a parser (found by the fuzzers in fuzz/, or written by hand
// for a bug fixed in issue #6) are kept in fuzz/regressions/. Each must now give either a
// result or an InputError: *.toml files go to parse_scene_text, everything else to parse_msh.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/errors.hpp"
#include "mesh/msh_reader.hpp"
#include "model/scene.hpp"

namespace fs = std::filesystem;
using namespace contact3d;

namespace {

std::vector<fs::path> regression_files() {
  std::vector<fs::path> out;
  const fs::path dir = fs::path(CONTACT3D_SOURCE_DIR) / "fuzz" / "regressions";
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file() && e.path().filename().string()[0] != '.' && e.path().extension() != ".md")
        out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Same convention as fuzz/fuzz_scene.cpp: a first line "--set k=v" is an override.
void parse_scene_input(std::string text) {
  std::vector<std::string> overrides;
  if (text.rfind("--set ", 0) == 0) {
    const auto nl = text.find('\n');
    overrides.push_back(text.substr(6, nl == std::string::npos ? std::string::npos : nl - 6));
    text = nl == std::string::npos ? std::string() : text.substr(nl + 1);
  }
  parse_scene_text(text, "/nonexistent", overrides);
}

}  // namespace

TEST(RegressionInputs, DirectoryIsNotEmpty) { EXPECT_FALSE(regression_files().empty()); }

TEST(RegressionInputs, EachGivesAResultOrAnInputError) {
  for (const auto& p : regression_files()) {
    SCOPED_TRACE(p.filename().string());
    const std::string data = slurp(p);
    try {
      if (p.extension() == ".toml") {
        parse_scene_input(data);
      } else {
        const Mesh m = parse_msh(data, p.filename().string());
        const int n = static_cast<int>(m.nodes.size());
        for (const auto& t : m.tets)
          for (int v : t) ASSERT_TRUE(v >= 0 && v < n);
        for (const auto& t : m.triangles)
          for (int v : t) ASSERT_TRUE(v >= 0 && v < n);
      }
    } catch (const InputError& e) {
      EXPECT_GT(std::string(e.what()).size(), 10u);  // a message a person can act on
    } catch (const std::exception& e) { ADD_FAILURE() << "unexpected exception (not InputError): " << e.what(); }
  }
}
