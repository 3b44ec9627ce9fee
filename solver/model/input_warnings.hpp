// Warnings and notes about the scene and mesh as given, said before anything is solved: what a
// converged run would otherwise hide (a material that locks, a modulus in the wrong unit, a load on
// the contact face, a load entered twice, volumes meshed side by side without being joined). None
// stops the solve; errors are the mesh checks' and the scene parser's.
#pragma once

#include "contact/face_thickness.hpp"
#include "fem/elasticity.hpp"
#include "mesh/mesh.hpp"
#include "model/contact_solver.hpp"
#include "model/scene.hpp"

namespace contact3d {

// Appends to res.warnings and res.notes; `materials`: each tetrahedron's (tet_materials); `thickness`:
// the run's one measurement of the body over Γc (contact/face_thickness.hpp).
void warn_about_inputs(const Scene& scene, const Mesh& mesh, const TetMaterials& materials,
                       const FaceThicknessOnce& thickness, SolveResult& res);

}  // namespace contact3d
