// What a run reports at one state of its solve (a fixed-point step, or the final answer), derived
// from that state's displacement u and multipliers λ (5.4): the status of every cell of T_H, the
// nodal contact fields on Γc (lumped L2 projection of the cellwise multipliers) and the stress of
// every tetrahedron (P1: constant per tet). The writers in io/ only format these.
//
// Sign conventions (documented in the README): contact_pressure = λ_n >= 0 is the pressure the
// foundation exerts on the body; tangential_traction = (λ_t1, λ_t2) in the plane's axes is the
// friction force per area the foundation exerts on the body (it opposes the slip where the body
// slides).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "fem/elasticity.hpp"
#include "mesh/mesh.hpp"
#include "model/contact_solver.hpp"
#include "model/scene.hpp"

namespace contact3d {

// One state: nodal displacement (3 per mesh node), λ = [λ_n | λ_t1 | λ_t2] and the radii c_i.
struct StateView {
  const Eigen::VectorXd& u;
  const Eigen::VectorXd& lambda;
  const Eigen::VectorXd& radius;
};
inline StateView final_state(const SolveResult& res) { return {res.u, res.lambda, res.radius}; }
inline StateView step_state(const SolveStep& s) { return {s.u, s.lambda, s.radius}; }

enum CellStatus : int { kSeparated = 0, kStick = 1, kSlip = 2 };

// Status of each cell: separated (λ_n <= 1e-6 max λ_n), slip (‖λ_t‖ >= (1 − 1e-3) c_i), else stick.
std::vector<int> cell_status(int n_cells, const Eigen::VectorXd& lambda, const Eigen::VectorXd& radius);
bool has_friction(int n_cells, const Eigen::VectorXd& lambda);

// Nodal fields on Γc (zero elsewhere), one value per mesh node: the cells' multipliers and radii
// averaged by the nodes' hat functions, as forces per unit area of Γc itself (the multipliers are per
// unit of its projection onto the plane: equal on a flat face).
struct ContactNodeFields {
  Eigen::VectorXd pressure, traction_t1, traction_t2, radius, friction;
  std::vector<int> status;  // separated unless a pressed cell covers part of the node; then stick or slip by weight
};
ContactNodeFields contact_node_fields(const Mesh& mesh, const Scene& scene, const SolveResult& res, const StateView& s);

// Cauchy stress of every tetrahedron, Voigt order (xx, yy, zz, yz, xz, xy), and its von Mises value.
struct TetStress {
  std::vector<Eigen::Matrix<double, 6, 1>> voigt;
  std::vector<double> von_mises;
  Eigen::Matrix3d tensor(std::size_t tet) const;  // the symmetric 3×3 matrix
};
TetStress tet_stresses(const Mesh& mesh, const TetMaterials& materials, const Eigen::VectorXd& u);

// The largest principal strain of the P1 field u (3 per mesh node) in absolute value, and the
// tetrahedron where it is: linear elasticity holds for small strains, a few percent at most.
struct StrainPeak {
  double value = 0;
  std::size_t tet = 0;
  double bulk = 0;  // the strain that 99% of the body's volume stays below (a peak far above it is local)
};
StrainPeak largest_strain(const Mesh& mesh, const Eigen::VectorXd& u);

// The gap to the foundation after the displacement u: height of node v above the plane plus u'_3.
double plane_gap(const Mesh& mesh, const FoundationFrame& frame, const Eigen::VectorXd& u, int v);
// The tangential part (u'_1, u'_2, 0) of a displacement u' given in the plane's frame, in the user's axes.
Eigen::Vector3d tangential_part(const FoundationFrame& frame, const Eigen::Vector3d& local);

// The contact resultants of one state, in the plane's frame (N): ∫ λ over the cells.
struct ContactResultants {
  double normal = 0, t1 = 0, t2 = 0;
  double friction_torque = 0;  // moment of the friction force about Γc's centroid, along the plane's normal (N m)
  std::array<double, 3> area{0, 0, 0};  // cell area by CellStatus (m²)
};
ContactResultants contact_resultants(const SolveResult& res, const StateView& s);
// The whole contact force on the body from the cells, in the plane's frame: (−∫λ_t1, −∫λ_t2, ∫λ_n) (N).
Eigen::Vector3d contact_force_in_plane_frame(const SolveResult& res);

}  // namespace contact3d
