// MUMPS's failures as errors, the same words whichever route called it (mumps_backend.cpp directly,
// petsc_route.cpp through PETSc): INFOG(1) = −13, an allocation that failed on some rank, is the
// user's to change (exit 2, base/errors.hpp); any other negative INFOG(1) a failure of MUMPS itself.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include "base/errors.hpp"

namespace contact3d::distributed {

// MUMPS's counts of entries (INFOG(29), INFOG(2) with −13) above 2^31 come back negative, in millions.
inline double mumps_count(std::int64_t reported) { return reported >= 0 ? double(reported) : -1e6 * double(reported); }

// Throws for INFOG(1) < 0 in `what` (e.g. "the MUMPS factorization"); nothing for INFOG(1) >= 0.
inline void throw_if_mumps_failed(int infog1, std::int64_t infog2, const std::string& what) {
  if (infog1 >= 0) return;
  if (infog1 == -13)
    throw InputError("not enough memory for " + what + ": allocating " +
                     std::to_string(static_cast<long long>(mumps_count(infog2))) +
                     " entries failed on one of the ranks (INFOG(1) = -13); run more ranks, on more machines, "
                     "keep the factor on disk (solver.out_of_core_dir), or use a coarser mesh");
  throw std::runtime_error("MUMPS failed in " + what + " (INFOG(1) = " + std::to_string(infog1) +
                           ", INFOG(2) = " + std::to_string(infog2) + ")");
}

}  // namespace contact3d::distributed
