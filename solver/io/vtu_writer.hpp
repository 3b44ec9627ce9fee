// ParaView files of one state of a solve (a fixed-point step or the final answer): the whole body
// (body.vtu) and the contact face Γc (contact.vtu), each with every field, so that any time step
// of solution.pvd shows the same things. The fields are computed in model/solution_fields.hpp;
// this file only formats them (VTK XML UnstructuredGrid, ASCII or binary as output.vtu says).
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
#include "io/vtu_format.hpp"
#include "mesh/mesh.hpp"
#include "model/solution_fields.hpp"

namespace contact3d {

// What every state's files share, built once per run: the inputs, which mesh nodes lie on Γc, and
// for each contact triangle the tetrahedron behind it and its contact group.
struct VtuContext {
  VtuContext(const Scene& scene, const Mesh& mesh, const SolveResult& res, const TetMaterials& materials);
  const Scene& scene;
  const Mesh& mesh;
  const SolveResult& res;
  const TetMaterials& materials;
  std::vector<char> on_face;              // per mesh node
  std::vector<int> face_tet, face_group;  // per triangle of Γc
  vtu::Encoding encoding;                 // output.vtu resolved for this mesh
};

// body.vtu and (when the scene has a contact face) contact.vtu of one state; the state's fields
// (nodal contact fields, stresses) are computed once for both files.
void write_state_vtus(const std::filesystem::path& body_file, const std::filesystem::path& contact_file,
                      const VtuContext& ctx, const StateView& state);

}  // namespace contact3d
