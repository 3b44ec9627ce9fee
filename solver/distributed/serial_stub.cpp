// The serial build's distributed backend: none (see backend.hpp).
#include <sys/resource.h>

#include "base/errors.hpp"
#include "distributed/backend.hpp"

namespace contact3d::distributed {

bool available() { return false; }

Session::Session(int&, char**&) {}
Session::~Session() = default;
int Session::serve() { return 0; }
void Session::finish(int) {}

std::unique_ptr<DualProblem> make_mumps_dual_problem(const DualProblemInput&, StageClock&, const MumpsOptions&) {
  // Refused before any work by model/contact_solver.cpp's require_backend; a safety net here.
  throw InputError("the distributed backend (MUMPS) is not in this build: `make build-mpi`");
}

int ranks() { return 1; }

std::string core_binding_note() { return ""; }

std::vector<double> peak_memory_per_rank_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return {static_cast<double>(u.ru_maxrss) / 1024.0};
}

}  // namespace contact3d::distributed
