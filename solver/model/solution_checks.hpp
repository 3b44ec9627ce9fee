// What a solve says about its own answer: after the recovery, warnings and notes where the answer is
// not what the user may think it is — out of equilibrium, no contact anywhere, nodes through the
// foundation off Γc or inside cells, a contact zone narrower than a few cells, strains a linear model
// does not describe, friction where the body has lifted off, a law with a jump — each with its cause
// and what to change. Also the measures contact.cell_size = "auto" decides by (unresolved()).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "contact/partition.hpp"
#include "fem/dof_map.hpp"
#include "mesh/mesh.hpp"
#include "model/contact_solver.hpp"
#include "model/scene.hpp"

namespace contact3d {

// The cells (× h) contact.cell_size = "auto" takes where 2h leaves the contact zone unresolved, or
// where the body is thinner than a cell of 2h (contact_solver.cpp); smaller ones make Q ill-conditioned.
inline constexpr double kRefinedCellSize = 1.5;

// Every check below on a recovered solve, in the order the run prints them. `u_max`: the body's
// largest deformation (largest_deformation); `rigid_removed`: it is less a rigid motion (held by
// contact alone, or imposed by prescribed values). Sets res.penetration_ratio.
void check_answer(const Scene& scene, const Mesh& mesh, double u_max, bool rigid_removed, SolveResult& res);

// A body that does not move at all (with or without contact): a warning that nothing loads it, or that its
// loads act only on nodes whose displacement is prescribed.
void flag_motionless(const Scene& scene, SolveResult& res);

// The answer's warning or note on its largest strain (also for a scene without contact); sets
// res.largest_strain.
void flag_large_strain(const Mesh& mesh, SolveResult& res);

// A scene without contact groups: the foundation plane holds nothing, which a note says where nodes
// start or end below it (the deepest named), so a body pushed through it is not solved in silence —
// a warning where the whole body starts on or above the plane (a contact group forgotten, likely).
void note_body_below_plane_without_contact(const Mesh& mesh, SolveResult& res);

// The nodes penetrate by more than 10% of the body's largest deformation (res.penetration_ratio):
// the contact zone is not resolved by its cells.
bool unresolved(const SolveResult& res);

// The largest nodal displacement of `u_free` (free dofs) less the rigid motion the prescribed values
// impose and less its least-squares fit by the rigid motions `held` (n_free × k; none: nothing removed).
double largest_deformation(const Mesh& mesh, const DofMap& dofs, const Eigen::VectorXd& u_free,
                           const Eigen::MatrixXd& held);

// "H = 0.05" (the cell size asked for), or the range of a graded partition's rectangles.
std::string cell_sizes(const SolveResult& res);
// A penetration against the body's largest displacement, to go before "the … displacement": "3.1% of",
// "150% of", or "3.1e+05 times" past 1000%.
std::string share_of_displacement(double ratio);

// The cells that carry a normal force: those with more than 1e-3 of the largest cell force (λ_n · area).
std::vector<int> cells_pressed(const Eigen::VectorXd& lambda, const Partition& partition);
// The covariance of the centres of `cells` (all cells where empty): its smaller eigenvalue says how
// far they spread across their narrowest direction.
Eigen::Matrix2d centroid_spread(const Partition& partition, std::vector<int> cells);

}  // namespace contact3d
