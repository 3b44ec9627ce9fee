#include "linalg/blas_threads.hpp"

#include <dlfcn.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

namespace contact3d {
namespace {

double monotonic_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// /proc/stat's "cpu" line: user nice system idle iowait irq softirq steal (guest time is in user).
bool read_machine(std::uint64_t& busy, std::uint64_t& total) {
  std::ifstream in("/proc/stat");
  std::string label;
  std::uint64_t user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0, softirq = 0, steal = 0;
  if (!(in >> label >> user >> nice >> system >> idle >> iowait >> irq >> softirq >> steal) || label != "cpu")
    return false;
  busy = user + nice + system + irq + softirq + steal;
  total = busy + idle + iowait;
  return true;
}

// /proc/self/stat's utime, stime, cutime, cstime (fields 14-17), counted after the command name's ')'.
bool read_own(std::uint64_t& own) {
  std::ifstream in("/proc/self/stat");
  std::string line;
  if (!std::getline(in, line)) return false;
  const std::size_t close = line.rfind(')');
  if (close == std::string::npos) return false;
  std::istringstream fields(line.substr(close + 1));
  std::string skip;
  for (int field = 3; field <= 13; ++field) fields >> skip;  // state … cmajflt
  std::uint64_t utime = 0, stime = 0;
  long long cutime = 0, cstime = 0;
  if (!(fields >> utime >> stime >> cutime >> cstime)) return false;
  own = utime + stime + static_cast<std::uint64_t>(std::max(0LL, cutime) + std::max(0LL, cstime));
  return true;
}

using SetThreads = void (*)(int);
SetThreads openblas_setter() { return reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads")); }

bool thread_count_set_by_user() {
  for (const char* name : {"OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "GOTO_NUM_THREADS"})
    if (const char* value = std::getenv(name); value && *value) return true;
  return false;
}

}  // namespace

CpuSnapshot cpu_snapshot() {
  CpuSnapshot s;
  s.wall = monotonic_seconds();
  s.valid = read_machine(s.machine_busy, s.machine_total) && read_own(s.own);
  return s;
}

double busy_cores_elsewhere(const CpuSnapshot& from, const CpuSnapshot& to, int cores) {
  if (!from.valid || !to.valid || to.machine_total <= from.machine_total || cores <= 0) return 0;
  const double total = static_cast<double>(to.machine_total - from.machine_total);
  const double busy = static_cast<double>(to.machine_busy - from.machine_busy);
  const double own = static_cast<double>(to.own) - static_cast<double>(from.own);
  return std::clamp((busy - own) / total * cores, 0.0, static_cast<double>(cores));
}

int usable_cores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) != 0) return static_cast<int>(std::max(1L, sysconf(_SC_NPROCESSORS_ONLN)));
  return std::max(1, CPU_COUNT(&set));
}

BlasThreadChoice current_blas_threads() {
  BlasThreadChoice choice;
  using GetThreads = int (*)();
  const auto get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  if (!get) return choice;
  choice.before = choice.threads = std::max(1, get());
  choice.cores = static_cast<int>(std::max(1L, sysconf(_SC_NPROCESSORS_ONLN)));
  choice.user_set = thread_count_set_by_user();
  return choice;
}

BlasThreadChoice fit_blas_threads_to_idle_cores(const CpuSnapshot& since, double min_seconds) {
  BlasThreadChoice choice = current_blas_threads();
  const SetThreads set = openblas_setter();
  if (!set || choice.before == 0 || choice.user_set || choice.before == 1 || !since.valid) return choice;
  if (const double waited = monotonic_seconds() - since.wall; waited < min_seconds)
    std::this_thread::sleep_for(std::chrono::duration<double>(min_seconds - waited));
  choice.busy_elsewhere = busy_cores_elsewhere(since, cpu_snapshot(), choice.cores);
  const int idle = static_cast<int>(std::lround(choice.cores - choice.busy_elsewhere));
  choice.threads = std::clamp(idle, 1, choice.before);
  if (choice.threads != choice.before) set(choice.threads);
  return choice;
}

BlasThreadChoice share_cores_among_ranks(int ranks_on_machine) {
  BlasThreadChoice choice = current_blas_threads();
  choice.ranks_on_machine = std::max(1, ranks_on_machine);
  const SetThreads set = openblas_setter();
  if (!set || choice.before == 0 || choice.user_set) return choice;
  const int share = std::max(1, choice.cores / choice.ranks_on_machine);
  choice.threads = std::clamp(std::min(usable_cores(), share), 1, choice.before);
  if (choice.threads != choice.before) set(choice.threads);
  return choice;
}

}  // namespace contact3d
