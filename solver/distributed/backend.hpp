// The distributed backend: the same dual problem on MUMPS 5.5 under MPI, with PETSc 3.18
// (`make build-mpi`, `mpirun -np P build-mpi/contact3d solve SCENE`). Rank 0 runs the solver as in
// the serial build — it reads the mesh, runs the dual QP and the fixed point and writes the
// outputs — but never holds K: every rank assembles the columns of K for its share of the nodes
// (rank 0 sends each rank only the tets around its nodes, fem/mesh_part.hpp) and keeps its part of
// [K 𝔹ᵀ; 𝔹 0] and of MUMPS's factor, then serves rank 0's requests (factorize, solve, release,
// report memory) until it finishes. Q comes from MUMPS's Schur complement on the multipliers
// (S = −Q, dense on rank 0), w = K⁻¹(f − 𝔹ᵀλ) from MUMPS's interior solve (ICNTL(26) = 0), K·w for
// the residuals element by element. MUMPS is called directly with the nested dissection the
// CHOLMOD path uses as its pivot order (ICNTL(7) = 1; from the node graph, as K is nowhere whole):
// PETSc's interface cannot pass an ordering to a Cholesky with a Schur complement, and MUMPS's own
// AMD fills 1.3-1.5× more. The PETSc route (MatFactorSetSchurIS on an MPISBAIJ matrix, K assembled
// on rank 0 and scattered, then freed there; petsc_route.hpp, a module loaded only for that route)
// stays selectable; its matrix carries the six rigid-body modes as its near-null space
// (MatSetNearNullSpace, checked on the ranks against rank 0's K·R), what PETSc's algebraic multigrid
// needs for elasticity. The direct route has no PETSc matrix to carry them.
//
// In the serial build the same interface exists: available() is false, Session does nothing and
// make_mumps_dual_problem throws an InputError saying how to get the backend.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "base/stage_clock.hpp"
#include "linalg/blas_threads.hpp"
#include "linalg/dual_problem.hpp"

namespace contact3d::distributed {

bool available();

// For main(): starts MPI (MPI_Init) and ends it, with PETSc if the PETSc route started it
// (petsc_route.hpp); on ranks other than 0, main calls serve(), which returns when rank 0's
// Session ends.
class Session {
 public:
  Session(int& argc, char**& argv);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  bool is_root() const { return rank_ == 0; }
  int ranks() const { return size_; }
  // With several ranks, each rank's OpenBLAS threads were set to its share of the machine's cores
  // (share_cores_among_ranks); with one, nothing was set (threads 0) and main fits them itself.
  const BlasThreadChoice& blas_threads() const { return blas_; }
  // A rank other than 0: serves rank 0's commands until it stops; returns rank 0's exit code.
  int serve();
  // Rank 0, at the end: stops the other ranks, handing them `exit_code` (the session's end stops them
  // with 0 where this was not called).
  void finish(int exit_code);

 private:
  int rank_ = 0, size_ = 1;
  BlasThreadChoice blas_;
  bool started_ = false;
  bool finished_ = false;
};

// Rank 0: the dual problem with MUMPS (laps `clock` at "factorization" and "dual"), called directly
// with our nested dissection as the pivot order, or through PETSc's interface (MUMPS's own AMD:
// PETSc cannot pass an ordering to MUMPS's Cholesky with a Schur complement).
enum class MumpsRoute { Direct, ThroughPetsc };
struct MumpsOptions {
  MumpsRoute route = MumpsRoute::Direct;
  // Non-empty (direct route only): MUMPS's out-of-core mode (ICNTL(22) = 1). Each rank writes its
  // part of the factor to files in this directory on its own machine during the factorization and
  // reads them back in every solve; in memory it holds only the fronts being factored (n = 40
  // brick, 2 ranks: 2463 / 2202 MiB per rank against 4092 / 3915 in core, results/
  // distributed_out_of_core.md). MUMPS deletes the files when the factor is released.
  std::string out_of_core_dir;
};
std::unique_ptr<DualProblem> make_mumps_dual_problem(const DualProblemInput& input, StageClock& clock,
                                                     const MumpsOptions& options = {});

// Rank 0: a note when the ranks together may use fewer cores than the machine has (Open MPI binds
// each rank to one core when np <= 2, so a single rank's BLAS threads share one core: MUMPS's
// factorization 5.2 s instead of 3.6 s on the n = 24 brick); empty otherwise.
std::string core_binding_note();

// Rank 0: the number of ranks and each rank's peak resident memory (MiB), in rank order.
int ranks();
std::vector<double> peak_memory_per_rank_mib();

}  // namespace contact3d::distributed
