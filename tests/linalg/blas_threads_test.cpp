// The machine sampler behind OpenBLAS's thread count (blas_threads.hpp): the arithmetic of busy
// cores elsewhere, a busy child process counted as elsewhere, a count the user set left alone, and
// ranks on one machine sharing its cores.
#include <gtest/gtest.h>

#include <dlfcn.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "linalg/blas_threads.hpp"

using namespace contact3d;

TEST(BlasThreads, BusyCoresElsewhereIsTheMachinesBusyShareLessOwnTime) {
  CpuSnapshot from, to;
  from.valid = to.valid = true;
  to.machine_total = 200;  // 2 cores, 100 ticks each
  to.machine_busy = 150;   // 1.5 cores busy …
  to.own = 50;             // … of which 0.5 this process's
  EXPECT_DOUBLE_EQ(busy_cores_elsewhere(from, to, 2), 1.0);
  to.own = 200;  // tick rounding: never below 0
  EXPECT_DOUBLE_EQ(busy_cores_elsewhere(from, to, 2), 0.0);
  to.valid = false;  // no /proc: nothing known, nothing reduced
  EXPECT_DOUBLE_EQ(busy_cores_elsewhere(from, to, 2), 0.0);
}

TEST(BlasThreads, ABusyProcessBesideThisOneCountsAsBusyElsewhere) {
  const CpuSnapshot from = cpu_snapshot();
  ASSERT_TRUE(from.valid);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // spins until killed
    volatile unsigned long spin = 0;
    for (;;) spin = spin + 1;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  const CpuSnapshot to = cpu_snapshot();
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  const int cores = static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN));
  // The child held most of a core for the interval (others may add to it, never take from it).
  EXPECT_GT(busy_cores_elsewhere(from, to, cores), 0.5);
}

TEST(BlasThreads, ACountTheUserSetIsLeftAlone) {
  setenv("OPENBLAS_NUM_THREADS", "2", 1);
  const BlasThreadChoice choice = fit_blas_threads_to_idle_cores(cpu_snapshot(), 0.0);
  unsetenv("OPENBLAS_NUM_THREADS");
  if (choice.before == 0) GTEST_SKIP() << "the BLAS is not OpenBLAS";
  EXPECT_TRUE(choice.user_set);
  EXPECT_EQ(choice.threads, choice.before);
  EXPECT_LT(choice.busy_elsewhere, 0);  // not even sampled
}

TEST(BlasThreads, RanksOnOneMachineShareItsCores) {
  unsetenv("OPENBLAS_NUM_THREADS");
  unsetenv("OMP_NUM_THREADS");
  unsetenv("GOTO_NUM_THREADS");
  const BlasThreadChoice start = current_blas_threads();
  if (start.before == 0) GTEST_SKIP() << "the BLAS is not OpenBLAS";
  using SetThreads = void (*)(int);
  const auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  ASSERT_NE(set, nullptr);
  // As many ranks as cores: one thread each, whatever OpenBLAS started with.
  const BlasThreadChoice crowded = share_cores_among_ranks(start.cores);
  EXPECT_EQ(crowded.before, start.before);
  EXPECT_EQ(crowded.threads, 1);
  EXPECT_EQ(crowded.ranks_on_machine, start.cores);
  EXPECT_EQ(current_blas_threads().threads, 1);
  // Twice as many ranks as cores (oversubscribed): still one, never zero.
  EXPECT_EQ(share_cores_among_ranks(2 * start.cores).threads, 1);
  // One rank: the count OpenBLAS chose for this process (its usable cores) stays.
  set(start.before);
  EXPECT_EQ(share_cores_among_ranks(1).threads, start.before);
  // A count the user set is left alone, even when crowded.
  setenv("OPENBLAS_NUM_THREADS", "2", 1);
  const BlasThreadChoice user = share_cores_among_ranks(2 * start.cores);
  unsetenv("OPENBLAS_NUM_THREADS");
  EXPECT_TRUE(user.user_set);
  EXPECT_EQ(user.threads, start.before);
  set(start.before);
}
