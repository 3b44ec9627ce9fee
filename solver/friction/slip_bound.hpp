// The disc radii of (5.3): c_i = ∫_{R_i} F(φ_h) g dS / meas_2(R_i), φ_h the P1 interpolant of
// the nodal slip ‖w_t‖ on Γc. Exact: each cell piece is cut along the level lines
// φ_h = t_k of the law's breakpoints, so F∘φ_h is linear on every sub-polygon and its
// integral is area × value at the centroid.
#pragma once

#include <Eigen/Core>

#include "contact/partition.hpp"
#include "friction/friction_law.hpp"

namespace contact3d {

// phi_nodes: φ at every mesh node (only contact-face nodes are read).
Eigen::VectorXd disc_radii(const ContactFace& face, const Partition& partition, const FrictionLaw& law,
                           double slip_bound, const Eigen::VectorXd& phi_nodes);

}  // namespace contact3d
