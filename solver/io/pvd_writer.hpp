// The fixed-point history for ParaView: steps/contact_step_<k>.vtu (the contact face Γc with
// the displacement after the k-th Tresca solve, its slip ‖u_t‖ and F(‖u_t‖)) and solution.pvd,
// a collection with one time step per fixed-point step (time = k) plus the final body.vtu
// (part 1, at the last step). The multipliers of intermediate steps are not kept, so the
// per-step files carry kinematic fields only; contact.vtu has the final tractions.
#pragma once

#include <filesystem>

#include "mesh/mesh.hpp"
#include "model/contact_solver.hpp"
#include "model/scene.hpp"

namespace contact3d {

// Writes nothing when the scene has no contact face. Returns the number of steps written.
int write_solution_steps(const std::filesystem::path& dir, const Scene& scene, const Mesh& mesh, const SolveResult& res);

}  // namespace contact3d
