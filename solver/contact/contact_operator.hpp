// The contact operator 𝔹 = [M B¹; M B²; M B³] of (5.4): row i of the normal block is the
// functional v ↦ ∫_{R_i} v_n dS with v_n = -v_3 (the foundation's outward normal is (0,0,-1) as
// seen from the body); rows of the tangential blocks are v ↦ ∫_{R_i} v_1 dS and v ↦ ∫_{R_i} v_2 dS.
// The integrals are over R_i in the plane, of the P1 fields on Γc's projection. Columns are free dofs.
// A frictionless scene has the normal block only.
#pragma once

#include <vector>

#include <Eigen/SparseCore>

#include "base/multiplier_layout.hpp"

#include "contact/partition.hpp"
#include "fem/dof_map.hpp"

namespace contact3d {

struct ContactOperator {
  Eigen::SparseMatrix<double> B;  // (r or 3r) x n_free
  // b: the rows at w = 0, so that the constraints read on 𝔹w + b — the prescribed displacement
  // components of contact nodes (∫_{R_i} of their share) minus, in the normal rows, ∫_{R_i} d dS
  // with d the initial gap (Γc's height above the foundation).
  Eigen::VectorXd offset;
  int r = 0;  // number of cells
  bool with_friction = true;
  MultiplierLayout layout() const { return {r, with_friction}; }
  int rows() const { return layout().size(); }
};

ContactOperator make_contact_operator(const ContactFace& face, const Partition& partition, const DofMap& dofs,
                                      bool with_friction);

// The stability condition (5.1) asks 𝔹 for full row rank (then Q = 𝔹K⁻¹𝔹ᵀ is positive definite for
// any K): the rows of `B` whose pivot in a sparse LDLᵀ of the Gram matrix of its rows scaled to unit
// length (sparse: only cells sharing nodes couple) falls below 1e-11, i.e. rows dependent on the
// others; empty when 𝔹 has full row rank. Without forming Q (the matrix-free dual).
std::vector<int> dependent_rows(const Eigen::SparseMatrix<double>& B);

}  // namespace contact3d
