#include "qp/lumped_preconditioner.hpp"

#include <cmath>
#include <utility>

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

// R = Dᵀ S over the directions `rows`: row j holds direction rows[j]'s weights on the original multipliers.
Eigen::SparseMatrix<double> restriction(const BoxDiscQP& qp, const std::vector<Direction>& d,
                                        const std::vector<Eigen::Index>& rows) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(2 * rows.size());
  for (std::size_t j = 0; j < rows.size(); ++j) {
    const Direction& e = d[static_cast<std::size_t>(rows[j])];
    const Eigen::Index row = static_cast<Eigen::Index>(j);
    entries.emplace_back(row, e.a, e.w_a * qp.entry_factor(e.a));
    if (e.b >= 0) entries.emplace_back(row, e.b, e.w_b * qp.entry_factor(e.b));
  }
  Eigen::SparseMatrix<double> R(static_cast<Eigen::Index>(rows.size()), qp.size());
  R.setFromTriplets(entries.begin(), entries.end());
  return R;
}

}  // namespace

LumpedPreconditioner::LumpedPreconditioner(const BoxDiscQP& qp, const std::vector<Direction>& d,
                                           Eigen::VectorXd inverse_diagonal)
    : inverse_diagonal_(std::move(inverse_diagonal)) {
  for (std::size_t j = 0; j < d.size(); ++j)
    if (!(d[j].shift > 0)) lumped_rows_.push_back(static_cast<Eigen::Index>(j));
  if (!qp.lumped || lumped_rows_.empty()) return;
  const Eigen::SparseMatrix<double> R = restriction(qp, d, lumped_rows_);
  const Eigen::SparseMatrix<double> Rt = R.transpose();
  stiffness_ = R * qp.lumped->stiffness * Rt;
  const Eigen::SparseMatrix<double> G = R * qp.lumped->gram * Rt;
  gram_.compute(G);
  if (gram_.info() != Eigen::Success) return;
  // A pivot that vanished against the largest says R𝔹 is (numerically) rank-deficient.
  const Eigen::VectorXd pivots = gram_.vectorD();
  usable_ = pivots.minCoeff() > 1e-12 * pivots.maxCoeff();
}

Eigen::VectorXd LumpedPreconditioner::lumped_part(const Eigen::VectorXd& r) const {
  Eigen::VectorXd s(static_cast<Eigen::Index>(lumped_rows_.size()));
  for (std::size_t j = 0; j < lumped_rows_.size(); ++j) s[static_cast<Eigen::Index>(j)] = r[lumped_rows_[j]];
  return s;
}

Eigen::VectorXd LumpedPreconditioner::apply_lumped(const Eigen::VectorXd& s) const {
  const Eigen::VectorXd x = gram_.solve(s);
  return factor_ * gram_.solve(Eigen::VectorXd(stiffness_ * x));
}

Eigen::VectorXd LumpedPreconditioner::apply(const Eigen::VectorXd& r) const {
  Eigen::VectorXd out = r.cwiseProduct(inverse_diagonal_);
  const Eigen::VectorXd t = apply_lumped(lumped_part(r));
  for (std::size_t j = 0; j < lumped_rows_.size(); ++j) out[lumped_rows_[j]] = t[static_cast<Eigen::Index>(j)];
  return out;
}

void LumpedPreconditioner::match_energy(const Eigen::VectorXd& r) {
  factor_ = 1;
  const Eigen::VectorXd s = lumped_part(r);
  const double lumped = s.dot(apply_lumped(s)), diagonal = s.dot(lumped_part(inverse_diagonal_).cwiseProduct(s));
  if (lumped > 0 && diagonal > 0 && std::isfinite(lumped)) factor_ = diagonal / lumped;
}

}  // namespace contact3d
