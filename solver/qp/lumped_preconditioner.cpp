#include "qp/lumped_preconditioner.hpp"

#include <cmath>

namespace contact3d {

LumpedOperators make_lumped_operators(const Eigen::SparseMatrix<double>& B, const Eigen::SparseMatrix<double>& K) {
  LumpedOperators lumped;
  lumped.gram = (B * B.transpose()).pruned();
  const Eigen::SparseMatrix<double> BK = B * K;  // K symmetric, both triangles stored
  lumped.stiffness = (BK * B.transpose()).pruned();
  return lumped;
}

double lumped_operator_bytes(const LumpedOperators& lumped) {
  constexpr double kBytesPerEntry = sizeof(double) + sizeof(int);
  return kBytesPerEntry * static_cast<double>(lumped.gram.nonZeros() + lumped.stiffness.nonZeros());
}

namespace {

// R = Dᵀ S: row j holds direction j's weights on the original multipliers.
Eigen::SparseMatrix<double> restriction(const BoxDiscQP& qp, const std::vector<Direction>& d) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(2 * d.size());
  for (std::size_t j = 0; j < d.size(); ++j) {
    const Direction& e = d[j];
    const Eigen::Index row = static_cast<Eigen::Index>(j);
    entries.emplace_back(row, e.a, e.w_a * qp.entry_factor(e.a));
    if (e.b >= 0) entries.emplace_back(row, e.b, e.w_b * qp.entry_factor(e.b));
  }
  Eigen::SparseMatrix<double> R(static_cast<Eigen::Index>(d.size()), qp.size());
  R.setFromTriplets(entries.begin(), entries.end());
  return R;
}

}  // namespace

LumpedPreconditioner::LumpedPreconditioner(const BoxDiscQP& qp, const std::vector<Direction>& d) {
  if (!qp.lumped || d.empty()) return;
  const Eigen::SparseMatrix<double> R = restriction(qp, d);
  const Eigen::SparseMatrix<double> Rt = R.transpose();
  stiffness_ = R * qp.lumped->stiffness * Rt;
  const Eigen::SparseMatrix<double> G = R * qp.lumped->gram * Rt;
  gram_.compute(G);
  if (gram_.info() != Eigen::Success) return;
  // A pivot that vanished against the largest says R𝔹 is (numerically) rank-deficient.
  const Eigen::VectorXd pivots = gram_.vectorD();
  usable_ = pivots.minCoeff() > 1e-12 * pivots.maxCoeff();
}

Eigen::VectorXd LumpedPreconditioner::apply(const Eigen::VectorXd& r) const {
  const Eigen::VectorXd x = gram_.solve(r);
  return factor_ * gram_.solve(Eigen::VectorXd(stiffness_ * x));
}

void LumpedPreconditioner::match_energy(const Eigen::VectorXd& r, const Eigen::VectorXd& inverse_diagonal) {
  factor_ = 1;
  const double lumped = r.dot(apply(r)), diagonal = r.dot(r.cwiseProduct(inverse_diagonal));
  if (lumped > 0 && diagonal > 0 && std::isfinite(lumped)) factor_ = diagonal / lumped;
}

}  // namespace contact3d
