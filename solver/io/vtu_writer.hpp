// ParaView files of one state of a solve (a fixed-point step or the final answer): the whole body
// (body.vtu) and the contact face Γc (contact.vtu), each with every field, so that any time step
// of solution.pvd shows the same things. The fields are computed in model/solution_fields.hpp;
// this file only formats them (ASCII VTK XML UnstructuredGrid).
//
// Point data: displacement, gap (height above the foundation after the displacement), slip (u_t on
// Γc), contact_pressure (λ_n, the foundation's pressure on the body), tangential_traction (the
// friction traction the foundation exerts on the body, user axes), traction_on_body (pressure plus
// friction, the whole contact traction on the body), friction_coefficient F(‖u_t‖) and
// contact_status (0 separated, 1 stick, 2 slip); body.vtu also displacement_norm and
// on_contact_face. Cell data: stress (the Cauchy stress tensor, 9 components, row-major),
// von_mises and physical_group (on contact.vtu those of the tetrahedron behind each triangle).
#pragma once

#include <filesystem>

#include "fem/elasticity.hpp"
#include "mesh/mesh.hpp"
#include "model/solution_fields.hpp"

namespace contact3d {

struct VtuContext {
  const Scene& scene;
  const Mesh& mesh;
  const SolveResult& res;
  const TetMaterials& materials;
};

void write_body_vtu(const std::filesystem::path& file, const VtuContext& ctx, const StateView& state);
// Writes nothing when the scene has no contact face.
void write_contact_vtu(const std::filesystem::path& file, const VtuContext& ctx, const StateView& state);

}  // namespace contact3d
