#include "qp/reduced_cg.hpp"

#include <algorithm>
#include <functional>
#include <optional>

#include <Eigen/Eigenvalues>
#include <Eigen/Sparse>

#include "qp/lumped_preconditioner.hpp"

namespace contact3d {
namespace {

// diag(Dᵀ diag(Q) D) + shift: a sliding direction's weights spread over two of Q's diagonal entries
// (the coupling Q_ab between its two tangents is left out; it is a preconditioner).
Eigen::VectorXd reduced_diagonal(const BoxDiscQP& qp, const std::vector<Direction>& d) {
  const Eigen::VectorXd q = qp.diagonal();
  Eigen::VectorXd diagonal(static_cast<Eigen::Index>(d.size()));
  for (std::size_t j = 0; j < d.size(); ++j) {
    const Direction& e = d[j];
    double v = e.w_a * e.w_a * q[e.a] + e.shift;
    if (e.b >= 0) v += e.w_b * e.w_b * q[e.b];
    diagonal[static_cast<Eigen::Index>(j)] = v > 0 ? v : 1.0;
  }
  return diagonal;
}

using FineLevel = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

// The two-level (balancing) preconditioner: on the coarse space Z (the coarse groups' indicator
// vectors restricted to the directions, BoxDiscQP::coarse_group) the system is solved exactly, on
// the rest by the fine level M⁻¹ (the lumped preconditioner or the diagonal):
//   P r = Z E⁻¹ Zᵀ r + (I − Z E⁻¹ Yᵀ) M⁻¹ (I − Y E⁻¹ Zᵀ) r,   Y = A Z, E = Zᵀ A Z.
// P is symmetric positive definite, and PA has the eigenvalue 1 on Z and the fine level's spectrum
// deflated of Z elsewhere. On a thin slab the smooth modes (the plate's bending, where Q is large)
// spread the diagonally scaled spectrum over four decades; deflating them cuts CG's products
// three- to fivefold. Added to D⁻¹ instead (additive), the same coarse solve did not cut them.
// Y = Dᵀ Q (D Z) + shift · Z takes Q D Z from the cache (CoarseProducts), recomputing (by one
// blocked product) only the groups whose directions changed since the last Newton step.
class TwoLevel {
 public:
  TwoLevel(const BoxDiscQP& qp, const std::vector<Direction>& d, FineLevel fine) : fine_(std::move(fine)) {
    const int groups = *std::max_element(qp.coarse_group.begin(), qp.coarse_group.end()) + 1;
    const Eigen::Index k = static_cast<Eigen::Index>(d.size());
    std::vector<Eigen::Triplet<double>> entries;
    for (Eigen::Index j = 0; j < k; ++j) {
      const Direction& e = d[static_cast<std::size_t>(j)];
      entries.emplace_back(j, qp.coarse_group[static_cast<std::size_t>(e.a)], e.w_a);
      if (e.b >= 0) entries.emplace_back(j, qp.coarse_group[static_cast<std::size_t>(e.b)], e.w_b);
    }
    Z_.resize(k, groups);
    Z_.setFromTriplets(entries.begin(), entries.end());
    const Eigen::MatrixXd& QDZ = update_products(qp, d, groups);
    Y_.resize(k, groups);
    for (Eigen::Index j = 0; j < k; ++j) {
      const Direction& e = d[static_cast<std::size_t>(j)];
      Y_.row(j) = e.w_a * QDZ.row(e.a) + e.shift * Eigen::RowVectorXd(Z_.row(j));
      if (e.b >= 0) Y_.row(j) += e.w_b * QDZ.row(e.b);
    }
    Eigen::MatrixXd E = Z_.transpose() * Y_;
    E = 0.5 * (E + E.transpose()).eval();
    // Pseudo-inverse by eigenvalues: groups without a direction leave E singular.
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(E);
    const double floor = 1e-12 * eig.eigenvalues().cwiseAbs().maxCoeff();
    const Eigen::VectorXd inverse =
        eig.eigenvalues().unaryExpr([floor](double v) { return v > floor ? 1.0 / v : 0.0; });
    E_inverse_ = eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
  }

  int products() const { return products_; }  // columns of Q (D Z) recomputed: one product by Q each

  Eigen::VectorXd apply(const Eigen::VectorXd& r) const {
    const Eigen::VectorXd coarse = E_inverse_ * (Z_.transpose() * r);
    Eigen::VectorXd t = fine_(r - Y_ * coarse);
    t -= Z_ * (E_inverse_ * (Y_.transpose() * t));
    return t + Z_ * coarse;
  }

 private:
  // D Z in full size, and Q D Z updated where it changed.
  const Eigen::MatrixXd& update_products(const BoxDiscQP& qp, const std::vector<Direction>& d, int groups) {
    CoarseProducts& cache = qp.coarse_products ? *qp.coarse_products : own_;
    const Eigen::MatrixXd DZ = prolong(d, Eigen::MatrixXd(Z_), qp.size());
    const bool same_shape = cache.DZ.rows() == DZ.rows() && cache.DZ.cols() == DZ.cols();
    std::vector<Eigen::Index> changed;
    for (Eigen::Index g = 0; g < groups; ++g)
      if (!same_shape || cache.DZ.col(g) != DZ.col(g)) changed.push_back(g);
    if (!same_shape) cache.QDZ = Eigen::MatrixXd::Zero(DZ.rows(), groups);
    if (!changed.empty()) {
      Eigen::MatrixXd delta(DZ.rows(), static_cast<Eigen::Index>(changed.size()));
      for (std::size_t c = 0; c < changed.size(); ++c)
        delta.col(static_cast<Eigen::Index>(c)) = same_shape
                                                      ? Eigen::VectorXd(DZ.col(changed[c]) - cache.DZ.col(changed[c]))
                                                      : Eigen::VectorXd(DZ.col(changed[c]));
      // In single precision where the problem has it: Y only shapes the preconditioner, which stays
      // symmetric positive definite for any Y (E symmetrized), so its rounding costs no accuracy.
      const Eigen::MatrixXd Qdelta = qp.apply_block_single(delta);
      for (std::size_t c = 0; c < changed.size(); ++c)
        cache.QDZ.col(changed[c]) += Qdelta.col(static_cast<Eigen::Index>(c));
    }
    products_ = static_cast<int>(changed.size());
    cache.DZ = DZ;
    return cache.QDZ;
  }

  FineLevel fine_;
  int products_ = 0;
  Eigen::SparseMatrix<double> Z_;
  Eigen::MatrixXd Y_, E_inverse_;
  CoarseProducts own_;  // where the problem keeps no products between steps
};

}  // namespace

namespace {

// b − A y from the start `y` (empty: y = 0, the residual b), the product counted in `result`.
Eigen::VectorXd start_residual(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::VectorXd& b,
                               Eigen::VectorXd& y, ReducedCgResult& result) {
  if (y.size() != b.size()) {
    y = Eigen::VectorXd::Zero(b.size());
    return b;
  }
  ++result.iterations;
  return b - reduced_product(qp, d, y);
}

// The CG iterations from y with residual r (both updated), preconditioned by `precondition`;
// `flexible`: β of Polak-Ribière, for a preconditioner symmetric only up to rounding.
void iterate_cg(const BoxDiscQP& qp, const std::vector<Direction>& d, const ReducedPreconditioner& precondition,
                bool single, bool flexible, double tolerance, int max_iterations, Eigen::VectorXd& y, Eigen::VectorXd r,
                ReducedCgResult& result, const CgHeartbeat& beat = {}) {
  Eigen::VectorXd z = precondition(r);
  Eigen::VectorXd p = z;
  double rz = r.dot(z);
  while (result.iterations < max_iterations) {
    const Eigen::VectorXd Ap = reduced_product(qp, d, p, single);
    ++result.iterations;
    if (single) ++result.single_products;
    if (beat) beat(result);
    const double curvature = p.dot(Ap);
    if (!(curvature > 0)) break;  // not positive definite in this direction (rounding): stop here
    const double alpha = rz / curvature;
    y += alpha * p;
    const Eigen::VectorXd r_before = flexible ? r : Eigen::VectorXd();
    r -= alpha * Ap;
    result.residual = r.norm();
    if (result.residual <= tolerance) {
      result.converged = true;
      break;
    }
    z = precondition(r);
    const double rz_next = r.dot(z);
    const double beta = flexible ? std::max(0.0, (rz_next - r_before.dot(z)) / rz) : rz_next / rz;
    p = z + beta * p;
    rz = rz_next;
  }
}

// The residual r of the start y, and a result that has converged where r already meets `tolerance`.
ReducedCgResult start(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::VectorXd& b, double tolerance,
                      Eigen::VectorXd& y, Eigen::VectorXd& r) {
  ReducedCgResult result;
  r = start_residual(qp, d, b, y, result);
  result.residual = r.norm();
  result.converged = result.residual <= tolerance;
  return result;
}

}  // namespace

ReducedCgResult solve_reduced_cg(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::VectorXd& b,
                                 double tolerance, int max_iterations, Eigen::VectorXd& y, const CgHeartbeat& beat) {
  Eigen::VectorXd r;
  ReducedCgResult result = start(qp, d, b, tolerance, y, r);
  if (result.converged) return result;
  const Eigen::VectorXd inverse_diagonal = reduced_diagonal(qp, d).cwiseInverse();
  FineLevel fine = [&inverse_diagonal](const Eigen::VectorXd& v) {
    return Eigen::VectorXd(v.cwiseProduct(inverse_diagonal));
  };
  // The lumped preconditioner only as the fine level of the two-level one: it is good on the
  // oscillating modes and poor on the smooth ones, which the coarse space takes (alone on the paper's
  // brick it took 1 216 products against the diagonal's 881).
  const bool coarse_space = !qp.coarse_group.empty() && !d.empty();
  std::optional<LumpedPreconditioner> lumped;
  if (coarse_space && qp.lumped) {
    lumped.emplace(qp, d, inverse_diagonal);
    if (lumped->usable()) {
      lumped->match_energy(r);
      fine = [&lumped](const Eigen::VectorXd& v) { return lumped->apply(v); };
    }
  }
  std::optional<TwoLevel> two_level;
  if (coarse_space) {
    two_level.emplace(qp, d, fine);
    result.coarse_products = two_level->products();
    result.iterations += result.coarse_products;
  }
  const bool single = qp.has_single_products() && tolerance >= kSingleCgReduction * result.residual;
  const ReducedPreconditioner precondition = [&](const Eigen::VectorXd& v) {
    return two_level ? two_level->apply(v) : fine(v);
  };
  iterate_cg(qp, d, precondition, single, false, tolerance, max_iterations, y, r, result, beat);
  return result;
}

ReducedCgResult solve_reduced_cg(const BoxDiscQP& qp, const std::vector<Direction>& d, const Eigen::VectorXd& b,
                                 double tolerance, int max_iterations, Eigen::VectorXd& y,
                                 const ReducedPreconditioner& preconditioner) {
  Eigen::VectorXd r;
  ReducedCgResult result = start(qp, d, b, tolerance, y, r);
  if (result.converged) return result;
  iterate_cg(qp, d, preconditioner, false, true, tolerance, max_iterations, y, r, result);
  return result;
}

}  // namespace contact3d
