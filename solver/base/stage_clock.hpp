// StageClock: wall time per stage of a solve, appended in order as (stage, seconds); with `cpu`
// also the process CPU time (all threads, getrusage) as "cpu_<stage>" — on a shared machine the
// CPU ratios are the steadier measure (benchmarks).
#pragma once

#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include <sys/resource.h>

namespace contact3d {

using StageTimes = std::vector<std::pair<std::string, double>>;

class StageClock {
 public:
  explicit StageClock(StageTimes& out, bool cpu = false) : out_(out), cpu_(cpu) {}
  // Ends the stage running since the previous lap (or construction) and names it.
  void lap(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    out_.emplace_back(stage, std::chrono::duration<double>(now - last_).count());
    last_ = now;
    if (cpu_) {
      const double c = cpu_seconds();
      out_.emplace_back("cpu_" + stage, c - last_cpu_);
      last_cpu_ = c;
    }
  }

 private:
  static double cpu_seconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
  }
  StageTimes& out_;
  bool cpu_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
  double last_cpu_ = cpu_ ? cpu_seconds() : 0;
};

}  // namespace contact3d
