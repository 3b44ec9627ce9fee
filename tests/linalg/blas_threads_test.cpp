// The machine sampler behind OpenBLAS's thread count (blas_threads.hpp): the arithmetic of busy
// cores elsewhere, a busy child process counted as elsewhere, and a count the user set left alone.
#include <gtest/gtest.h>

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
