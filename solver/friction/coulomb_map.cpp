#include "friction/coulomb_map.hpp"

namespace contact3d {
namespace {

double scale_of(const Eigen::VectorXd& v) {
  const double s = v.size() ? v.cwiseAbs().maxCoeff() : 0.0;
  return s > 0 ? s : 1.0;
}

}  // namespace

CoulombMap::CoulombMap(TrescaStep& tresca, int n_contact_nodes, int n_cells, bool slip_dependent_law)
    : tresca_(tresca), n_nodes_(n_contact_nodes), n_cells_(n_cells), slip_starts_at_zero_(slip_dependent_law) {}

SlipEvaluation CoulombMap::operator()(const Eigen::VectorXd& state, double qp_rtol) {
  const bool first = phi_scale_ == 0;
  const double s_phi = first ? 1.0 : phi_scale_, s_g = first ? 1.0 : g_scale_;
  const Eigen::VectorXd phi = s_phi * state.head(n_nodes_);
  const Eigen::VectorXd g = s_g * state.tail(n_cells_);
  SlipEvaluation eval = tresca_.solve(phi, g, qp_rtol);
  const Eigen::VectorXd pressure = tresca_.normal_pressure();
  if (first) {
    phi_scale_ = scale_of(eval.slip);
    g_scale_ = scale_of(pressure);
  }
  // The first solve (g = 0) is frictionless: it gives the first normal pressure, but its slip is not
  // fed back. The slip starts at φ⁰ = 0, the sticking start of (5.7), as in the Tresca iteration:
  // starting from the frictionless slip instead (every node at F's far end) made a jump law's
  // sticking front creep back node by node (37 steps instead of 7 on the hexagonal prism) and, where
  // the problem has several solutions, ended at another one than the sticking start reaches.
  Eigen::VectorXd next(size());
  if (first && slip_starts_at_zero_)
    next << Eigen::VectorXd::Zero(n_nodes_), pressure / g_scale_;
  else
    next << eval.slip / phi_scale_, pressure / g_scale_;
  eval.slip = std::move(next);
  // The derivative and the prediction of the scaled map, from the second solve on (the first one's
  // slip is not fed back).
  if (eval.ok && !first) {
    eval.derivative = [this, s_phi, s_g](const Eigen::VectorXd& v) {
      const TrescaStep::Derivative d = tresca_.derivative(s_phi * v.head(n_nodes_), s_g * v.tail(n_cells_));
      Eigen::VectorXd out(size());
      out << d.slip / phi_scale_, d.normal_pressure / g_scale_;
      return out;
    };
    eval.derivative_products = [this] { return tresca_.sensitivity_products(); };
    eval.predict = [this, s_phi, s_g](const Eigen::VectorXd& x) {
      const TrescaStep::Prediction p = tresca_.predict(s_phi * x.head(n_nodes_), s_g * x.tail(n_cells_));
      if (p.slip.size() == 0) return Eigen::VectorXd();
      Eigen::VectorXd out(size());
      out << p.slip / phi_scale_, p.normal_pressure / g_scale_;
      return out;
    };
  }
  return eval;
}

}  // namespace contact3d
