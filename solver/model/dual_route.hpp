// Which way the dual problem (5.5) is formed once the scene's size is known: the dense Q of the
// scene's solver.schur where Q and its working copies fit in the memory this process can get, else,
// for "auto" in the serial build, the matrix-free route (DualMethod::MatrixFree: the factor of K, no
// m × m array, each product through the factor). The caller measures the memory and says what it chose.
#pragma once

#include <optional>

#include "linalg/dual_problem.hpp"

namespace contact3d {

// `requested`: solver.schur as the scene states it; `resolved`: what "auto" became for the build
// (augmented; mumps in the distributed build). nullopt: the dense Q does not fit and nothing else
// may be taken (a dense method the scene named, or MUMPS, whose Schur complement is dense).
std::optional<DualMethod> dual_method_for_memory(DualMethod requested, DualMethod resolved, bool dense_Q_fits);

}  // namespace contact3d
