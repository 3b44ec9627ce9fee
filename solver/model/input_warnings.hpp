// Warnings and notes about the scene and mesh as given, said before anything is solved: what a
// converged run would otherwise hide (a material that locks, a modulus in the wrong unit, a load on
// the contact face, a load entered twice, volumes meshed side by side without being joined). None
// stops the solve; errors are the mesh checks' and the scene parser's.
#pragma once

#include <string>

#include "contact/face_thickness.hpp"
#include "fem/elasticity.hpp"
#include "mesh/mesh.hpp"
#include "model/contact_solver.hpp"
#include "model/scene.hpp"

namespace contact3d {

// Appends to res.warnings and res.notes; `dofs`: the prescribed components (make_dof_map); `materials`:
// each tetrahedron's (tet_materials); `thickness`: the run's one measurement of the body over Γc
// (contact/face_thickness.hpp).
void warn_about_inputs(const Scene& scene, const Mesh& mesh, const DofMap& dofs, const TetMaterials& materials,
                       const FaceThicknessOnce& thickness, SolveResult& res);

// Whether a warning of warn_about_inputs speaks of the answer's accuracy only (too few elements through
// a plate), not of a mistake in the input that could make a solve fail: a refusal does not cite it as
// its possible cause (a pull-off load's refusal did, and a cell size's).
bool warns_of_accuracy_only(const std::string& warning);

}  // namespace contact3d
