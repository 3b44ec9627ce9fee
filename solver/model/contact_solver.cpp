#include "model/contact_solver.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <memory>
#include <optional>

#include <sys/resource.h>

#include <Eigen/Dense>

#include "contact/contact_operator.hpp"
#include "fem/assembly.hpp"
#include "friction/slip_bound.hpp"
#include "base/errors.hpp"
#include "linalg/displacement_trace.hpp"
#include "linalg/dual_operator.hpp"
#include "linalg/sparse_cholesky.hpp"
#include "qp/jacobi_scaling.hpp"
#include "qp/ssn.hpp"

namespace contact3d {
namespace {

// Wall time per stage; with `cpu` also the process CPU time (all threads, getrusage) as
// "cpu_<stage>": on a shared machine the CPU ratios are the steadier measure (benchmarks).
class StageClock {
 public:
  explicit StageClock(std::vector<std::pair<std::string, double>>& out, bool cpu = false) : out_(out), cpu_(cpu) {}
  void lap(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    out_.emplace_back(stage, std::chrono::duration<double>(now - last_).count());
    last_ = now;
    if (cpu_) {
      const double c = cpu_seconds();
      out_.emplace_back("cpu_" + stage, c - last_cpu_);
      last_cpu_ = c;
    }
  }

 private:
  static double cpu_seconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
  }
  std::vector<std::pair<std::string, double>>& out_;
  bool cpu_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
  double last_cpu_ = cpu_ ? cpu_seconds() : 0;
};

// The yardsticks of total / factorization (benchmarks), in this process: one factorization of K
// as CHOLMOD orders it by itself ("reference_factorization"), and one with the ordering this
// solver uses ("reference_factorization_nd").
void time_reference_factorizations(const Eigen::SparseMatrix<double>& K, StageClock& clock) {
  { const SparseCholesky ref(K, FillOrdering::CholmodDefault); }
  clock.lap("reference_factorization");
  { const SparseCholesky ref(K, FillOrdering::QuotientNestedDissection); }
  clock.lap("reference_factorization_nd");
}

// Stability (5.1): 𝔹 has full row rank iff Q = 𝔹K⁻¹𝔹ᵀ is positive definite. Returns an
// estimate of cond(Q) (power iterations on Q and Q⁻¹); when its Cholesky fails or is
// near-singular, a pivoted LDLᵀ names the cells whose rows are dependent (and throws).
double check_stability(const Eigen::MatrixXd& Q, double lambda_max, const Partition& part, int r) {
  {  // the fast path: blocked Cholesky (several times faster than the pivoted LDLᵀ at 5000 rows)
    const Eigen::LLT<Eigen::MatrixXd> llt(Q);
    if (llt.info() == Eigen::Success) {
      const Eigen::VectorXd d = llt.matrixLLT().diagonal().cwiseAbs2();
      if (d.minCoeff() > 1e-11 * d.maxCoeff()) {
        // cond(Q) = λmax / λmin: power iteration on Q and (with the factor) on Q⁻¹.
        Eigen::VectorXd x = Eigen::VectorXd::Ones(Q.rows()).normalized();
        for (int k = 0; k < 30; ++k) x = llt.solve(x).normalized();
        const double lambda_min = x.dot(Q * x);
        return lambda_max / lambda_min;
      }
    }
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(Q);
  const Eigen::VectorXd d = ldlt.vectorD();
  const double dmax = d.cwiseAbs().maxCoeff();
  std::vector<int> bad;
  for (int k = 0; k < d.size(); ++k)
    if (!(d[k] > 1e-11 * dmax)) bad.push_back(k);
  if (bad.empty()) return dmax / d.minCoeff();
  // Map pivots back through the LDLT permutation to rows of 𝔹, then to cells.
  const auto& perm = ldlt.transpositionsP();
  Eigen::VectorXi order = Eigen::VectorXi::LinSpaced(d.size(), 0, static_cast<int>(d.size()) - 1);
  order = perm * order;  // pivot k of the LDLᵀ sits at row (P·idx)[k] of Q
  std::string cells;
  for (std::size_t k = 0; k < bad.size() && k < 8; ++k) {
    const int row = order[bad[k]], cell = row % r;
    const auto& c = part.cells[cell];
    cells += "\n  cell " + std::to_string(cell) + " [" + std::to_string(c.lo.x()) + ", " + std::to_string(c.hi.x()) +
             "] x [" + std::to_string(c.lo.y()) + ", " + std::to_string(c.hi.y()) + "], area " + std::to_string(c.area);
  }
  throw InputError("the multiplier partition violates the stability condition (5.1): " + std::to_string(bad.size()) +
                   " rows of the contact operator are linearly dependent, e.g." + cells +
                   "\nuse a larger contact.cell_size (H), e.g. twice the current one");
}

// Q without one solve per row of 𝔹. "augmented" factors [K 𝔹ᵀ; 𝔹 σI] (only the 3r multipliers
// ordered last; about 1.1 factorizations) and is what auto takes. "contactlast" keeps a dense
// nt x nt block of all contact dofs (nt³/3 extra flops, more memory) but a new 𝔹 would cost
// only dense work; "blocksolve" is the reference (pipeline/bench.py measures all three).
std::string choose_schur(SchurMethod m, int /*n_trailing*/, int n_dual) {
  if (m == SchurMethod::BlockSolve || n_dual == 0) return "blocksolve";
  if (m == SchurMethod::ContactLast) return "contactlast";
  return "augmented";
}

// u on Γc as the fixed point sees it: (u1, u2, u3) at every node of a contact triangle (the
// order of SolveResult::history_nodes; 0 at clamped components), and the slip |u_t| from it.
struct FaceDisplacement {
  std::vector<int> dofs;   // free dofs of the face nodes, by (node in triangle order, component)
  std::vector<int> slots;  // position of dofs[k] in the face vector
  std::vector<int> slot_of_node;  // mesh node -> first slot, or -1
  std::size_t size = 0;

  FaceDisplacement(SolveResult& res, std::size_t n_nodes) : slot_of_node(n_nodes, -1) {
    for (const auto& tri : res.face.triangles)
      for (int v : tri)
        if (slot_of_node[v] < 0) {
          slot_of_node[v] = static_cast<int>(3 * res.history_nodes.size());
          res.history_nodes.push_back(v);
        }
    size = 3 * res.history_nodes.size();
    for (std::size_t j = 0; j < res.history_nodes.size(); ++j)
      for (int c = 0; c < 3; ++c) {
        const int d = res.dofs.dof(res.history_nodes[j], c);
        if (d >= 0) { dofs.push_back(d); slots.push_back(static_cast<int>(3 * j) + c); }
      }
  }
  Eigen::VectorXd gather(const Eigen::VectorXd& w) const {
    Eigen::VectorXd out(dofs.size());
    for (std::size_t k = 0; k < dofs.size(); ++k) out[k] = w[dofs[k]];
    return out;
  }
  Eigen::VectorXd scatter(const Eigen::VectorXd& values) const {
    Eigen::VectorXd u_face = Eigen::VectorXd::Zero(size);
    for (std::size_t k = 0; k < slots.size(); ++k) u_face[slots[k]] = values[k];
    return u_face;
  }
  Eigen::VectorXd slip(const ContactFace& face, const Eigen::VectorXd& u_face) const {
    Eigen::VectorXd phi(face.nodes.size());
    for (std::size_t k = 0; k < face.nodes.size(); ++k) {
      const int p = slot_of_node[face.nodes[k]];
      phi[k] = std::hypot(u_face[p], u_face[p + 1]);
    }
    return phi;
  }
};

}  // namespace

std::pair<double, double> normal_violation(const Mesh& mesh, const ContactFace& face, const Eigen::VectorXd& u) {
  double l2sq = 0, inf = 0;
  for (const auto& tri : face.triangles) {
    Polygon poly = triangle_polygon(mesh.nodes[tri[0]].head<2>(), mesh.nodes[tri[1]].head<2>(), mesh.nodes[tri[2]].head<2>());
    const Eigen::Vector3d wn(-u[3 * tri[0] + 2], -u[3 * tri[1] + 2], -u[3 * tri[2] + 2]);
    inf = std::max(inf, wn.maxCoeff());
    if (wn.maxCoeff() <= 0) continue;
    std::vector<double> levels = {-wn[0], -wn[1], -wn[2]};
    poly = clip_by_levels(poly, levels);
    if (poly.empty()) continue;
    std::vector<double> values(poly.size());
    for (std::size_t k = 0; k < poly.size(); ++k) values[k] = std::max(0.0, poly[k].bary.dot(wn));
    l2sq += integral_linear_squared(poly, values);
  }
  return {std::sqrt(l2sq), std::max(inf, 0.0)};
}

SolveResult solve_scene(const Scene& scene, const Mesh& mesh, const ProgressCallback& progress) {
  SolveResult res;
  StageClock clock(res.seconds, scene.solver.reference_factorization);
  check_tet_orientation(mesh);
  res.dofs = make_dof_map(mesh, scene.clamped);
  if (res.dofs.n_free == 0) throw InputError("every node is clamped: nothing to solve");
  res.n_primal = res.dofs.n_free;
  const Eigen::SparseMatrix<double> K = assemble_stiffness(mesh, res.dofs, scene.material);
  const Eigen::VectorXd f = assemble_load(mesh, res.dofs, scene.tractions, scene.body_force);
  clock.lap("assembly");

  if (scene.contact.empty()) {  // no contact: one linear solve
    const SparseCholesky factor(K);
    res.factor_nonzeros = factor.factor_nonzeros();
    clock.lap("factorization");
    const Eigen::VectorXd w = factor.solve(f);
    res.u = expand_to_nodes(res.dofs, w);
    res.kkt.equilibrium = (K * w - f).norm() / std::max(f.norm(), 1e-300);
    res.n_mult = 1;
    res.converged = true;
    res.status = "converged";
    clock.lap("solve");
    if (scene.solver.reference_factorization) time_reference_factorizations(K, clock);
    return res;
  }

  res.face = make_contact_face(mesh, scene.contact, res.dofs);
  // H = k·h means k times the typical element extent in each direction (h_xy), so that an
  // anisotropic contact mesh gets rectangles of the same aspect; a length is used as given.
  res.cell_size = scene.cell_size_relative ? scene.cell_size * res.face.h_xy.x() : scene.cell_size;
  PartitionOptions cells;
  cells.cell_size = res.cell_size;
  cells.cell_size_y = scene.cell_size_relative ? scene.cell_size * res.face.h_xy.y() : 0.0;
  res.partition = make_grid_partition(mesh, res.face, cells);
  const bool with_friction = !scene.frictionless();
  const ContactOperator op = make_contact_operator(res.face, res.partition, res.dofs, with_friction);
  res.n_cells = op.r;
  res.n_dual = op.rows();
  clock.lap("contact");
  // Q is dense (n_dual²): refuse sizes that cannot fit rather than dying in the allocator.
  const double q_bytes = 8.0 * op.rows() * static_cast<double>(op.rows());
  if (q_bytes > 8.0 * (1ull << 30))
    throw InputError("the contact partition has " + std::to_string(op.r) + " cells (" + std::to_string(op.rows()) +
                     " multipliers): the dense dual operator would need " + std::to_string(q_bytes / (1ull << 30)) +
                     " GiB; use a larger contact.cell_size (H)");

  // One factorization that also yields Q without a solve per row of 𝔹: by default of the
  // augmented [K 𝔹ᵀ; 𝔹 σI] (Q = L₂₁L₂₁ᵀ), or of K with the contact dofs last (trailing block, dense
  // trsm/syrk), or plain K with block solves (the reference). It also serves K⁻¹f and the final w.
  const std::vector<int> trailing = contact_dofs(op.B);
  res.schur_method = choose_schur(scene.solver.schur, static_cast<int>(trailing.size()), op.rows());
  const bool contact_last = res.schur_method == "contactlast", augmented = res.schur_method == "augmented";
  std::unique_ptr<SparseCholesky> factor_ptr =
      contact_last ? std::make_unique<SparseCholesky>(K, trailing)
      : augmented  ? std::make_unique<SparseCholesky>(K, op.B)
                   : std::make_unique<SparseCholesky>(K);
  const SparseCholesky& factor = *factor_ptr;
  res.factor_nonzeros = factor.factor_nonzeros();
  clock.lap("factorization");

  // u on Γc per fixed-point step: a restricted back substitution (augmented factor only).
  FaceDisplacement face_u(res, mesh.nodes.size());
  std::optional<DisplacementTrace> trace;
  if (augmented) {
    trace.emplace(factor, f, face_u.dofs);
    res.step_solve_fraction = trace->work_fraction();
  }
  const Eigen::VectorXd u_free = trace ? trace->everywhere(Eigen::VectorXd::Zero(op.rows())) : Eigen::VectorXd();
  const DualOperator dual = contact_last ? make_dual_operator_schur(factor, op.B, f)
                            : augmented  ? make_dual_operator_augmented(factor, op.B, f, &u_free)
                                         : make_dual_operator(factor, op.B, f);
  clock.lap("dual");
  const double q_lambda_max = estimate_norm(dual.Q);  // once: for cond(Q) and for MPGP's step ᾱ
  res.stability_condition = check_stability(dual.Q, q_lambda_max, res.partition, op.r);
  clock.lap("stability");

  BoxDiscQP qp;
  qp.Q = &dual.Q;
  qp.h = dual.h;
  qp.r = op.r;
  qp.with_friction = with_friction;
  qp.radius = Eigen::VectorXd::Zero(op.r);
  qp.q_norm = 1.05 * q_lambda_max;
  MpgpSettings mpgp;
  mpgp.max_iterations = scene.solver.qp_max_iterations;
  mpgp.expansion = scene.solver.qp == QpVariant::MpgpProjectedCG ? ExpansionKind::ProjectedCG : ExpansionKind::FullGradient;
  res.qp_method = scene.solver.qp == QpVariant::Ssn ? "ssn" : scene.solver.qp == QpVariant::MpgpProjectedCG ? "mpgp_projcg" : "mpgp";

  // Solvers see the Jacobi-scaled problem unless the scene asks for the paper's plain one.
  std::optional<JacobiScaledQP> jacobi;
  if (scene.solver.qp_scaling == QpScaling::Jacobi) jacobi.emplace(qp);
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(op.rows());
  int products = 0;
  // One Tresca (or frictionless) solve for the radii of φ: warm-started λ, then w = K⁻¹(f − 𝔹ᵀλ)
  // on Γc (all that the next radii need; the whole w is recovered once, after the loop).
  auto tresca = [&](const Eigen::VectorXd& phi_contact, double rtol) {
    SlipEvaluation eval;
    if (with_friction) {
      Eigen::VectorXd phi_nodes = Eigen::VectorXd::Zero(mesh.nodes.size());
      for (std::size_t k = 0; k < res.face.nodes.size(); ++k) phi_nodes[res.face.nodes[k]] = phi_contact[k];
      qp.radius = disc_radii(res.face, res.partition, scene.law, scene.slip_bound, phi_nodes);
    }
    const BoxDiscQP& problem = jacobi ? jacobi->scaled(qp.radius) : qp;
    Eigen::VectorXd x = jacobi ? jacobi->to_scaled(lambda) : lambda;
    if (scene.solver.qp == QpVariant::Ssn) {
      SsnSettings ssn;
      ssn.rtol = rtol;
      ssn.max_iterations = scene.solver.qp_max_iterations;
      res.last_qp = solve_ssn(problem, x, ssn);
    } else {
      mpgp.rtol = rtol;
      res.last_qp = solve_mpgp(problem, x, mpgp);
    }
    lambda = jacobi ? jacobi->from_scaled(x) : x;
    Eigen::VectorXd u_face = face_u.scatter(
        trace ? trace->at(lambda) : face_u.gather(dual.u_free - factor.solve(Eigen::VectorXd(op.B.transpose() * lambda))));
    eval.ok = res.last_qp.status == QpStatus::Converged && u_face.allFinite();
    eval.qp_iterations = res.last_qp.iterations;
    eval.hessian_products = res.last_qp.hessian_products + 1;  // + w on Γc (counted as one K⁻¹ solve)
    products += eval.hessian_products;
    res.qp_iterations += res.last_qp.iterations;
    eval.slip = face_u.slip(res.face, u_face);
    res.u_history.push_back(std::move(u_face));
    res.slip_input = phi_contact;
    return eval;
  };

  const Eigen::VectorXd phi0 = Eigen::VectorXd::Zero(res.face.nodes.size());
  if (scene.law.depends_on_slip() && with_friction) {
    FixedPointSettings fp;
    fp.tol = scene.solver.fixed_point_tol;
    fp.max_iterations = scene.solver.fixed_point_max_iter;
    fp.anderson = scene.solver.fixed_point == FixedPointVariant::Anderson;
    fp.anderson_depth = scene.solver.anderson_depth;
    fp.inexact = scene.solver.inexact_fixed_point;
    res.fixed_point = solve_fixed_point(tresca, static_cast<int>(phi0.size()), fp, scene.solver.qp_rtol, progress);
    res.status = to_string(res.fixed_point.status);
    res.converged = res.fixed_point.status == FixedPointStatus::Converged;
  } else {
    const SlipEvaluation eval = tresca(phi0, scene.solver.qp_rtol);
    res.converged = eval.ok;
    res.status = eval.ok ? "converged" : "qp_" + to_string(res.last_qp.status);
    if (progress) progress({1, 0.0, eval.qp_iterations, eval.hessian_products, 0.0});
  }
  res.n_mult = products + 1;  // + h = 𝔹K⁻¹f; forming Q is not counted (not multiplications in the paper's sense)
  clock.lap("dual_solve");

  const Eigen::VectorXd w =
      trace ? trace->everywhere(lambda) : Eigen::VectorXd(dual.u_free - factor.solve(Eigen::VectorXd(op.B.transpose() * lambda)));
  res.lambda = lambda;
  res.radius = qp.radius;
  res.u = expand_to_nodes(res.dofs, w);
  res.kkt = kkt_residuals(K, f, op.B, op.r, with_friction, qp.radius, w, lambda, dual.h);
  std::tie(res.wn_plus_L2, res.wn_plus_inf) = normal_violation(mesh, res.face, res.u);
  if (!res.u.allFinite() || !res.lambda.allFinite())
    throw std::runtime_error("the solution is not finite (numerical breakdown); residuals could not be computed");
  clock.lap("postprocess");
  if (scene.solver.reference_factorization) {  // the yardstick for total / factorization, same process
    trace.reset();       // it points into our factor
    factor_ptr.reset();  // free our factor first: two big factors need not fit at once
    time_reference_factorizations(K, clock);
  }
  return res;
}

}  // namespace contact3d
