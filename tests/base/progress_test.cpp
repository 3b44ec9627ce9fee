// Tests of Progress (solver/base/progress.hpp): a Watch around a long call says, from its own thread,
// what still runs and for how long, stops when the call returns, and says nothing on a silent Progress.
#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "base/progress.hpp"

namespace contact3d {
namespace {

// beat() reads the clock once in 32 calls (cheap in MPGP's millisecond iterations); beat_each_call() on
// every call, for loops whose passes take seconds (a matrix-free Newton step's CG products), which were
// silent for minutes. A period of zero: a line whenever the clock is read.
TEST(Progress, BeatEachCallReadsTheClockEveryTime) {
  std::vector<std::string> lines;
  Progress progress([](const std::string&) {}, [&](const std::string& line) { lines.push_back(line); }, 0.0);
  const auto line = [] { return std::string("beat"); };
  progress.beat(line);  // starts the clock
  for (int k = 0; k < 5; ++k) progress.beat(line);
  EXPECT_TRUE(lines.empty());
  for (int k = 0; k < 3; ++k) progress.beat_each_call(line);
  EXPECT_EQ(lines.size(), 3u);
}

TEST(Progress, AWatchSaysWhatStillRunsUntilTheCallReturns) {
  std::mutex mutex;
  std::vector<std::string> lines;
  const Progress::Sink sink = [&](const std::string& line) {
    std::lock_guard<std::mutex> lock(mutex);
    lines.push_back(line);
  };
  const Progress progress(sink, sink, 2.0);
  const auto lines_so_far = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    return lines.size();
  };
  {
    const Progress::Watch watch(progress, "factorization", 0.05);
    // The long call: until two lines came (a loaded machine may wake the watch late; 10 s at most).
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (lines_so_far() < 2 && std::chrono::steady_clock::now() < give_up)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const std::size_t said = lines_so_far();
  ASSERT_GE(said, 2u);
  {
    std::lock_guard<std::mutex> lock(mutex);
    EXPECT_EQ(lines[0], "  factorization: still running, 0.05 s");
    EXPECT_EQ(lines[1], "  factorization: still running, 0.10 s");
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(120));  // ended with the call: nothing more
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(lines.size(), said);
}

TEST(Progress, AWatchOnASilentProgressSaysNothing) {
  const Progress silent;
  const Progress::Watch watch(silent, "mesh", 0.01);
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  SUCCEED();  // no sink to call, no thread started: nothing to crash on
}

}  // namespace
}  // namespace contact3d
