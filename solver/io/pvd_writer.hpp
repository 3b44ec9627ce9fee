// The run as a ParaView collection, solution.pvd: one time step per Tresca (or frictionless) solve
// — the fixed point's steps k = 1, 2, … (time = k), or the one solve — each with two parts, the
// whole body (part 0) and the contact face Γc (part 1), and every field on both
// (steps/body_<k>.vtu, steps/contact_<k>.vtu; the last step is the answer, body.vtu and
// contact.vtu, which write_results has written). With [output] steps = "final", only the answer,
// as one time step (time = number of solves).
#pragma once

#include <filesystem>

#include "io/vtu_writer.hpp"

namespace contact3d {

// Returns the number of time steps written. `dir` is a RunFolder's, which removed an earlier run's
// step files (stale steps of a longer run would mislead).
int write_solution_collection(const std::filesystem::path& dir, const VtuContext& ctx);

// Removes an earlier run's step files (steps/body_<k>.vtu, steps/contact_<k>.vtu) and the steps
// folder if that leaves it empty; any other file a user keeps there stays.
void remove_step_files(const std::filesystem::path& dir);

}  // namespace contact3d
