// Tests of RunFolder (solver/io/run_folder.*): what opening an output folder removes and what it keeps
// (the previous run's files and `make pipeline`'s report go, a user's own report.md stays), and that a
// folder whose steps/ another running solve writes in is refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "base/errors.hpp"
#include "io/run_folder.hpp"
#include "test_support.hpp"

namespace contact3d {
namespace {

std::filesystem::path fresh_folder(const std::string& name) { return testing::fresh_temp_folder("run_folder_" + name); }

void write(const std::filesystem::path& file, const std::string& text) { std::ofstream(file) << text; }

TEST(RunFolder, RemovesThePipelinesReportButKeepsTheUsersOwn) {
  const std::filesystem::path ours = fresh_folder("ours"), users = fresh_folder("users");
  write(ours / "report.md", std::string(kRunReportTitle) + "slab.toml\n\n- scene: `slab.toml`\n");
  write(ours / "summary.json", "{}");
  write(users / "report.md", "# My notes on this load case\n");
  {
    RunFolder a(ours, "solve");
    RunFolder b(users, "solve");
  }
  EXPECT_FALSE(std::filesystem::exists(ours / "report.md"));
  EXPECT_FALSE(std::filesystem::exists(ours / "summary.json"));
  EXPECT_TRUE(std::filesystem::exists(users / "report.md"));
  std::filesystem::remove_all(ours);
  std::filesystem::remove_all(users);
}

// A solve into A while another writes into A/steps: the first would write its step files into the
// second's folder (a helper's two runs ended mixed, both with exit 0).
TEST(RunFolder, RefusesAFolderWhoseStepsAnotherSolveWrites) {
  const std::filesystem::path dir = fresh_folder("nested");
  {
    RunFolder inner(dir / "steps", "solve");
    EXPECT_THROW(RunFolder outer(dir, "solve"), InputError);
  }
  EXPECT_NO_THROW(RunFolder outer(dir, "solve"));  // the inner solve has ended
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace contact3d
