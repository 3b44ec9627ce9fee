// Coulomb friction by successive approximations on the pair (φ, g): the slip bound g of the
// Tresca problem is the normal pressure λ_n of the previous solve, so at the fixed point the
// disc radii are c_i = F̄_i(φ)·λ_n,i (F̄_i the mean of F(φ_h) over cell R_i, (5.3) with g = λ_n).
// The state the fixed point iterates is [φ/s_φ ; g/s_g]: each block divided by a scale taken from
// the first solve (the frictionless one, g = 0), so the mixing and the step lengths compare
// dimensionless numbers; err(k) is the larger of the two blocks' relative changes. The start is
// (φ, g) = (0, 0): the first solve is frictionless and yields g = λ_n, while φ stays 0 (the
// sticking start of (5.7)) for the second when F depends on the slip.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "friction/fixed_point.hpp"
#include "friction/tresca_step.hpp"

namespace contact3d {

class CoulombMap {
 public:
  // `slip_dependent_law`: F depends on the slip, so the slip starts at φ⁰ = 0 after the frictionless
  // solve; with a constant F the slip does not enter the radii and the frictionless one is kept.
  CoulombMap(TrescaStep& tresca, int n_contact_nodes, int n_cells, bool slip_dependent_law);

  // G(x) for the scaled state x = [φ/s_φ ; g/s_g] (the SlipMap of the fixed point), with its
  // derivative from the second solve on (TrescaStep::derivative).
  SlipEvaluation operator()(const Eigen::VectorXd& state, double qp_rtol);

  int size() const { return n_nodes_ + n_cells_; }
  std::vector<int> blocks() const { return {n_nodes_, n_cells_}; }

 private:
  TrescaStep& tresca_;
  int n_nodes_, n_cells_;
  bool slip_starts_at_zero_;
  double phi_scale_ = 0, g_scale_ = 0;  // 0 until the first solve sets them
};

}  // namespace contact3d
