// Tests of write_file (solver/io/atomic_file.*): a file appears under its name only when complete, and
// a stopping signal's handler removes the ".partial" file being written at that moment.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "base/errors.hpp"
#include "io/atomic_file.hpp"
#include "test_support.hpp"

namespace contact3d {
namespace {

std::filesystem::path fresh_folder(const std::string& name) {
  return testing::fresh_temp_folder("atomic_file_" + name);
}

// What the SIGTERM handler calls while body.vtu is being written (a helper's stop left
// body.vtu.partial): the partial file goes; once written and renamed, nothing is removed.
TEST(AtomicFile, SignalHandlerRemovesThePartialFileBeingWritten) {
  const std::filesystem::path dir = fresh_folder("signal");
  const std::filesystem::path file = dir / "body.vtu", partial = dir / "body.vtu.partial";
  bool partial_existed = false, partial_left = true;
  // Without the signal's end that follows the handler, the write goes on and its rename finds no file.
  EXPECT_THROW(write_file(file,
                          [&](std::ostream& out) {
                            out << "first half";
                            out.flush();
                            partial_existed = std::filesystem::exists(partial);
                            remove_partial_file_for_signal();
                            partial_left = std::filesystem::exists(partial);
                          }),
               InputError);
  EXPECT_TRUE(partial_existed);
  EXPECT_FALSE(partial_left);
  EXPECT_FALSE(std::filesystem::exists(partial));
  EXPECT_FALSE(std::filesystem::exists(file));
}

TEST(AtomicFile, NothingIsRemovedOutsideAWrite) {
  const std::filesystem::path dir = fresh_folder("outside");
  const std::filesystem::path file = dir / "summary.json";
  write_file(file, [](std::ostream& out) { out << "{}"; });
  remove_partial_file_for_signal();
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "{}");
}

}  // namespace
}  // namespace contact3d
