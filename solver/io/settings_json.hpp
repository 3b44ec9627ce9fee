// The solver settings as resolved for a run (defaults filled in, enums by their scene names), so
// summary.json says exactly how a result was computed.
#pragma once

#include "io/json_writer.hpp"
#include "model/scene.hpp"

namespace contact3d {

inline void write_solver_settings(JsonWriter& j, const SolverSettings& s) {
  j.begin_object("settings");
  j.value("qp", name_of(s.qp.variant, kQpVariantNames)).value("qp_scaling", name_of(s.qp.scaling, kQpScalingNames));
  j.value("qp_precision", name_of(s.qp.precision, kQpPrecisionNames));
  j.value("qp_newton_systems", name_of(s.qp.newton_systems, kNewtonSystemsNames));
  j.value("qp_cg_preconditioner", name_of(s.qp.cg_preconditioner, kCgPreconditionerNames));
  j.value("qp_rtol", s.qp_rtol).value("qp_max_iterations", s.qp.max_iterations);
  j.value("fixed_point", name_of(s.fixed_point, kFixedPointVariantNames)).value("anderson_depth", s.anderson_depth);
  j.value("fixed_point_tail_err", s.fixed_point_tail_err).value("fixed_point_newton", s.fixed_point_newton);
  j.value("fixed_point_prediction", s.fixed_point_prediction);
  j.value("qp_rtol_per_err", s.qp_rtol_per_err);
  j.value("fixed_point_tol", s.fixed_point_tol).value("fixed_point_max_iter", s.fixed_point_max_iter);
  j.value("inexact_fixed_point", s.inexact_fixed_point).value("schur", name_of(s.dual_method, kDualMethodNames));
  j.value("reference_factorization", s.reference_factorization);
  j.value("out_of_core_dir", s.out_of_core_dir.string());
  j.end_object();
}

}  // namespace contact3d
