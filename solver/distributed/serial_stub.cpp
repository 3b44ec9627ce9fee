// The serial build's distributed backend: none (see backend.hpp).
#include <sys/resource.h>

#include "base/errors.hpp"
#include "distributed/backend.hpp"

namespace contact3d::distributed {

bool available() { return false; }

Session::Session(int&, char**&) {}
Session::~Session() = default;
void Session::serve() {}

std::unique_ptr<DualProblem> make_mumps_dual_problem(const DualProblemInput&, StageClock&, const MumpsOptions&) {
  throw InputError(
      "solver.schur = \"mumps\" or \"mumps_petsc\" needs the distributed build: `make build-mpi`, then `mpirun -np P "
      "build-mpi/contact3d solve SCENE`");
}

int ranks() { return 1; }

std::string core_binding_note() { return ""; }

std::vector<double> peak_memory_per_rank_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return {static_cast<double>(u.ru_maxrss) / 1024.0};
}

}  // namespace contact3d::distributed
