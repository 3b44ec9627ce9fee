// Writes what every solve leaves in its output folder: summary.json, contact_nodes.csv,
// contact_cells.csv, history.csv, body.vtu, contact.vtu and contact_cells.vtu (ParaView).
#pragma once

#include <filesystem>

#include "mesh/mesh.hpp"
#include "model/contact_solver.hpp"
#include "model/scene.hpp"

namespace contact3d {

struct RunInfo {
  std::string mesh_description;  // where the mesh came from
  double mesh_seconds = 0;
  double total_seconds = 0;
};

// Nodal fields on Γc derived from the cellwise multipliers (lumped L2 projection).
struct ContactNodeFields {
  Eigen::VectorXd pressure, traction_t1, traction_t2, radius, friction;  // per mesh node (0 off Γc)
  std::vector<int> status;  // 0 open, 1 stick, 2 slip (per mesh node)
};
// Status of each cell of T_H: 0 open (λ_n <= 1e-6 max λ_n), 2 slip (‖λ_t‖ >= (1 − 1e-3) c_i),
// 1 stick. A node's status is the one its surrounding cells carry most weight for.
std::vector<int> cell_status(const SolveResult& res);
// The gap to the foundation after the displacement: height of node v above the plane plus u'_3.
double plane_gap(const Mesh& mesh, const SolveResult& res, int v);
// The tangential part (u'_1, u'_2, 0) of a displacement u' given in the plane's frame, in the user's axes.
Eigen::Vector3d tangential_part(const FoundationFrame& frame, const Eigen::Vector3d& local);
ContactNodeFields contact_node_fields(const Mesh& mesh, const Scene& scene, const SolveResult& res);

void write_results(const std::filesystem::path& dir, const Scene& scene, const Mesh& mesh, const SolveResult& res,
                   const RunInfo& info);
void write_summary_json(const std::filesystem::path& file, const Scene& scene, const Mesh& mesh, const SolveResult& res,
                        const RunInfo& info);

}  // namespace contact3d
