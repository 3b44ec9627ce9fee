// TrescaStep: one evaluation of the map G of the successive approximations (5.7). For the slip φ
// at the contact nodes it sets the disc radii c(φ) (5.3), solves the dual QP (5.5) warm-started
// from the previous multipliers, and returns the slip ‖w_t‖ of w = K⁻¹(f − 𝔹ᵀλ) on Γc. It keeps
// the state the fixed point carries between steps (λ, the radii, counts) and, for the output, the
// multipliers and radii of every solve.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "contact/face_dofs.hpp"
#include "friction/fixed_point.hpp"
#include "linalg/dual_problem.hpp"
#include "qp/dual_qp_solver.hpp"

namespace contact3d {

// The radii c_i (5.3) for a slip φ at the contact nodes and a slip bound g per cell (size r;
// unused when frictionless).
using RadiusRule = std::function<Eigen::VectorXd(const Eigen::VectorXd& phi_contact, const Eigen::VectorXd& g)>;

class TrescaStep {
 public:
  // `dual`, `qp`, `face_dofs` and `face` must outlive the step; `slip_bound`: Tresca's g per cell.
  TrescaStep(const DualProblem& dual, DualQpSolver& qp, const FaceDofs& face_dofs, const ContactFace& face,
             RadiusRule radii, Eigen::VectorXd slip_bound);

  // G(φ): one Tresca solve with the QP tolerance `qp_rtol` (the SlipMap of the fixed point), with
  // its derivative (derivative()).
  SlipEvaluation operator()(const Eigen::VectorXd& phi, double qp_rtol);
  // One Tresca solve with radii c(φ, g) for a given slip bound g per cell (Coulomb: g = λ_n).
  SlipEvaluation solve(const Eigen::VectorXd& phi, const Eigen::VectorXd& g, double qp_rtol);

  // The derivative of the last solve's answer (the slip at the nodes and λ_n per cell) along a change
  // (v_φ, v_g) of its input (φ, g): the radii's difference quotient (c(φ, g) is a cell integral of
  // F(φ) times g, piecewise smooth), λ's sensitivity to the radii at the solution
  // (qp/radius_sensitivity.hpp), the displacement on Γc it moves (one K⁻¹ application, linear), and
  // the slip's difference quotient along it. Costs kDerivativeProducts in the paper's count (the
  // sensitivity's products by Q, one K⁻¹ on Γc); the first call after a solve also factors the
  // reduced system. On a matrix-free Q the sensitivity solves by CG: it costs that CG's products
  // (sensitivity_products()).
  struct Derivative {
    Eigen::VectorXd slip, normal_pressure;
  };
  Derivative derivative(const Eigen::VectorXd& v_phi, const Eigen::VectorXd& v_g);
  // The last solve's answer predicted at another input (φ, g): λ moved by its sensitivity to the
  // radii, λ + S·(c(φ, g) − c), with the friction law evaluated exactly in c(φ, g) (a jump stays a
  // jump), then the slip of the displacement on Γc that λ gives and max(λ_n, 0). Exact where the QP's
  // active sets do not change; a fixed point of it is what the fixed point's predicted steps seek.
  // Costs kDerivativeProducts, like one derivative; empty vectors when the sensitivity failed.
  using Prediction = Derivative;  // the same two fields, at a point instead of along a direction
  Prediction predict(const Eigen::VectorXd& phi, const Eigen::VectorXd& g);
  static constexpr int kDerivativeProducts = RadiusSensitivity::kProductsPerApply + 1;
  // What derivative() and predict() have cost so far, in K⁻¹ applications (part of products()).
  int sensitivity_products() const { return sensitivity_products_; }

  // Rigid motions held by the contact alone (model/held_by_contact.hpp): their values at the face
  // dofs (FaceDofs order, one column per motion). From then on u on Γc is w − Rμ, μ the QP's
  // equality multiplier of each solve (its change along a derivative is not followed).
  void add_rigid_motions(Eigen::MatrixXd face_field) { rigid_face_ = std::move(face_field); }

  const Eigen::VectorXd& lambda() const { return lambda_; }
  const Eigen::VectorXd& radius() const { return radius_; }
  const Eigen::VectorXd& slip_input() const { return slip_input_; }                     // φ of the last radii
  const Eigen::VectorXd& slip_bound_input() const { return slip_bound_input_; }         // g of the last radii
  Eigen::VectorXd normal_pressure() const { return lambda_.head(slip_bound_.size()); }  // λ_n per cell
  const QpResult& last_qp() const { return last_qp_; }
  int products() const { return products_; }  // K⁻¹ applications in the paper's sense
  int qp_iterations() const { return qp_iterations_; }
  int newton_steps() const { return newton_steps_; }        // semismooth Newton steps inside the QP solves
  int bordered_steps() const { return bordered_steps_; }    // of which through the factor of Q
  int feasible_steps() const { return feasible_steps_; }    // of which feasible descent steps (qp/ssn.hpp)
  int rounding_stops() const { return rounding_stops_; }    // QP solves stopped at their rounding floor
  int single_products() const { return single_products_; }  // of the products, those in single precision
  int coarse_products() const { return coarse_products_; }  // of the products, the two-level CG's blocked columns
  // u on Γc after the last solve (FaceDofs order, 3 per node).
  const Eigen::VectorXd& last_face_displacement() const { return last_face_; }
  // λ and the radii of every solve so far, in order (one value per multiplier: small).
  struct Solve {
    Eigen::VectorXd lambda, radius;
    Eigen::VectorXd rigid;  // μ: the rigid motions' amplitudes (empty without add_rigid_motions)
  };
  const std::vector<Solve>& history() const { return history_; }

 private:
  const DualProblem& dual_;
  DualQpSolver& qp_;
  const FaceDofs& face_dofs_;
  const ContactFace& face_;
  RadiusRule radii_;
  Eigen::VectorXd slip_bound_;
  Eigen::VectorXd lambda_, radius_, slip_input_, slip_bound_input_;
  QpResult last_qp_;
  int products_ = 0, qp_iterations_ = 0, newton_steps_ = 0, bordered_steps_ = 0, single_products_ = 0;
  int rounding_stops_ = 0, feasible_steps_ = 0;
  int coarse_products_ = 0;
  Eigen::VectorXd last_face_, last_slip_;  // u on Γc after the last solve, and its slip G(φ)
  std::vector<Solve> history_;
  Eigen::MatrixXd rigid_face_;  // R at the face dofs (no columns: none)
  // u on Γc (3 per node) for multipliers λ: w(λ) − R(μ + dμ), μ the last solve's (dμ empty: 0).
  Eigen::VectorXd face_displacement(const Eigen::VectorXd& lambda, const Eigen::VectorXd& dmu = {}) const;
  std::optional<RadiusSensitivity> sensitivity_;  // of the last solve, made by the first derivative() or predict()
  RadiusSensitivity* sensitivity();               // sensitivity_, made if need be; null when it failed
  int counted_products_ = 0;                      // sensitivity_->products() already in products_
  int sensitivity_products_ = 0;
  void count_sensitivity_products(const RadiusSensitivity* S);
};

}  // namespace contact3d
