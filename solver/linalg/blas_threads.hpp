// OpenBLAS's thread count fitted to the cores that other work leaves idle. A threaded BLAS call
// ends when every thread has done its share; on a core another process holds, a thread waits for
// its time slice, and CHOLMOD's supernodal factorization makes thousands of such calls. Measured
// on this 2-core machine with a test suite running beside the solve: the paper's brick at n = 16
// (12.6 GFlop factor) 5.8 s with two BLAS threads, 1.5 s with one; at n = 8, 1.37 s against 0.20 s.
// On an idle machine nothing changes. So the solve samples the machine's CPU time (/proc/stat)
// over an interval, takes away its own and its children's (gmsh, FreeFEM), and gives OpenBLAS the
// cores left idle, at least one. A thread count the user set (OPENBLAS_NUM_THREADS,
// OMP_NUM_THREADS, GOTO_NUM_THREADS) is left alone, and so is any BLAS other than OpenBLAS.
#pragma once

#include <cstdint>

namespace contact3d {

// CPU time of the whole machine and of this process with its waited-for children, in clock ticks.
struct CpuSnapshot {
  std::uint64_t machine_busy = 0, machine_total = 0;  // /proc/stat's first line, all cores
  std::uint64_t own = 0;                              // utime + stime + cutime + cstime
  double wall = 0;                                    // seconds on a monotonic clock
  bool valid = false;                                 // false where /proc cannot be read
};
CpuSnapshot cpu_snapshot();

// Cores kept busy by other processes between two snapshots (0 … cores): the machine's busy share
// of all cores, less this process's own time. Negative results (tick rounding) are 0.
double busy_cores_elsewhere(const CpuSnapshot& from, const CpuSnapshot& to, int cores);

struct BlasThreadChoice {
  int threads = 0;             // OpenBLAS's threads from now on (0: not OpenBLAS, untouched)
  int before = 0;              // its count before
  int cores = 0;               // cores of the machine
  double busy_elsewhere = -1;  // cores other processes kept busy (-1: not sampled)
  bool user_set = false;       // the environment fixed the count: left as it is
  int ranks_on_machine = 1;    // MPI ranks sharing this machine's cores (share_cores_among_ranks)
};

// Cores in this process's affinity mask (what mpirun's binding leaves it); the machine's where unknown.
int usable_cores();

// OpenBLAS's thread count as it is, unchanged (threads 0: not OpenBLAS).
BlasThreadChoice current_blas_threads();

// Samples the machine from `since` to now (waiting until `min_seconds` have passed, for enough
// clock ticks to count) and sets OpenBLAS's thread count to the idle cores: max(1, round(cores −
// busy elsewhere)), never more than it had.
BlasThreadChoice fit_blas_threads_to_idle_cores(const CpuSnapshot& since, double min_seconds = 0.05);

// Under mpirun, each rank on this machine: OpenBLAS starts one thread per core the process may
// use, so ranks that mpirun leaves unbound (--bind-to none) or binds to a whole socket (its default
// above 2 ranks) each start as many threads as the machine or socket has cores — P × C threads on C
// cores, and MUMPS's factorization waits on threads that wait for a core. Measured on this 2-core
// machine, the paper's brick, 2 ranks unbound: n = 16 0.63-0.75 s with one thread per rank against
// 1.13-1.28 s with two; n = 24 5.1 s against 7.8-14.5 s. Each rank gets max(1, min(the cores it may
// use, the machine's cores / `ranks_on_machine`)) threads, never more than it had; a count the user
// set is left alone.
BlasThreadChoice share_cores_among_ranks(int ranks_on_machine);

}  // namespace contact3d
