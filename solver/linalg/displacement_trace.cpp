#include "linalg/displacement_trace.hpp"

#include <algorithm>
#include <stdexcept>

#include "linalg/blas.hpp"

namespace contact3d {
namespace {

// Columns of supernode s that belong to K (not to the multipliers ordered last).
std::int64_t leading_columns(const SparseCholesky::Supernodes& L, std::int64_t s, std::int64_t first_trailing) {
  return std::max<std::int64_t>(0, std::min(L.super[s + 1], first_trailing) - L.super[s]);
}

}  // namespace

DisplacementTrace::DisplacementTrace(const SparseCholesky& factor, const Eigen::VectorXd& f,
                                     const std::vector<int>& dofs, const ForwardSolvedBlocks& W)
    : DisplacementTrace(factor, f, dofs, &W) {}

DisplacementTrace::DisplacementTrace(const SparseCholesky& factor, const Eigen::VectorXd& f,
                                     const std::vector<int>& dofs)
    : DisplacementTrace(factor, f, dofs, nullptr) {}

DisplacementTrace::DisplacementTrace(const SparseCholesky& factor, const Eigen::VectorXd& f,
                                     const std::vector<int>& dofs, const ForwardSolvedBlocks* W)
    : L_(factor.supernodes()), n_(factor.size()), dofs_(dofs), W_(W) {
  if (!W_ && !factor.augmented())
    throw std::logic_error("DisplacementTrace needs the augmented factor SparseCholesky(K, 𝔹), or W");
  if (W_ && W_->rows != n_) throw std::invalid_argument("DisplacementTrace: W and K sizes differ");
  if (f.size() != n_) throw std::invalid_argument("DisplacementTrace: load vector and K sizes differ");
  first_trailing_ = factor.augmented() ? L_.n - factor.trailing_size() : n_;
  position_.assign(L_.n, 0);
  for (std::int64_t k = 0; k < L_.n; ++k) position_[L_.perm[k]] = k;

  // Supernode of every column, and the leading supernodes in descending order.
  std::vector<std::int64_t> owner(L_.n);
  for (std::int64_t s = 0; s < L_.count; ++s)
    for (std::int64_t j = L_.super[s]; j < L_.super[s + 1]; ++j) owner[j] = s;
  for (std::int64_t s = L_.count - 1; s >= 0; --s)
    if (leading_columns(L_, s, first_trailing_) > 0) all_.push_back(s);

  // S's supernodes and their ancestors (parent = owner of the first row below the diagonal block).
  std::vector<char> mark(L_.count, 0);
  for (int d : dofs_) {
    if (d < 0 || d >= n_) throw std::invalid_argument("DisplacementTrace: dof out of range");
    for (std::int64_t s = owner[position_[d]]; s >= 0 && !mark[s];) {
      mark[s] = 1;
      const std::int64_t ncols = L_.super[s + 1] - L_.super[s], nrows = L_.pi[s + 1] - L_.pi[s];
      s = nrows > ncols ? owner[L_.rows[L_.pi[s] + ncols]] : -1;
    }
  }
  double touched = 0, total = 0;
  for (std::int64_t s : all_) {
    const double entries = double(leading_columns(L_, s, first_trailing_)) * double(L_.pi[s + 1] - L_.pi[s]);
    total += entries;
    if (mark[s]) {
      needed_.push_back(s);
      touched += entries;
    }
  }
  work_fraction_ = total > 0 ? touched / total : 0;

  // z = L₁₁⁻¹ P f by supernodal forward substitution (once).
  z_ = Eigen::VectorXd::Zero(L_.n);
  for (std::int64_t k = 0; k < L_.n; ++k)
    if (L_.perm[k] < n_) z_[k] = f[L_.perm[k]];
  std::vector<double> below;
  const int one = 1;
  const double zero = 0, plus_one = 1;
  for (auto it = all_.rbegin(); it != all_.rend(); ++it) {
    const std::int64_t s = *it, k1 = L_.super[s];
    const int nc = static_cast<int>(leading_columns(L_, s, first_trailing_));
    const int nrows = static_cast<int>(L_.pi[s + 1] - L_.pi[s]), nb = nrows - nc;
    const double* block = L_.values + L_.px[s];
    dtrsv_("L", "N", "N", &nc, block, &nrows, z_.data() + k1, &one);
    if (nb == 0) continue;
    below.assign(nb, 0.0);
    dgemv_("N", &nb, &nc, &plus_one, block + nc, &nrows, z_.data() + k1, &one, &zero, below.data(), &one);
    const std::int64_t* rows = L_.rows + L_.pi[s] + nc;
    for (int p = 0; p < nb; ++p) z_[rows[p]] -= below[p];
  }
}

Eigen::VectorXd DisplacementTrace::back_substitute(const Eigen::VectorXd& lambda,
                                                   const std::vector<std::int64_t>& supernodes) const {
  if (lambda.size() != (W_ ? W_->columns : L_.n - first_trailing_))
    throw std::invalid_argument("DisplacementTrace: λ has the wrong size");
  Eigen::VectorXd x = z_;
  if (W_) {  // z − Wλ on K's rows; the factor's own multipliers (if any) at zero
    x.tail(L_.n - n_).setZero();
    W_->subtract_product(lambda, x);
  } else {
    for (std::int64_t i = 0; i < lambda.size(); ++i) x[position_[n_ + i]] = lambda[i];
  }
  std::vector<double> gathered;
  const int one = 1;
  const double minus_one = -1, plus_one = 1;
  for (std::int64_t s : supernodes) {  // descending: every row below a supernode is already solved
    const std::int64_t k1 = L_.super[s];
    const int nc = static_cast<int>(leading_columns(L_, s, first_trailing_));
    const int nrows = static_cast<int>(L_.pi[s + 1] - L_.pi[s]), nb = nrows - nc;
    const double* block = L_.values + L_.px[s];
    if (nb > 0) {
      const std::int64_t* rows = L_.rows + L_.pi[s] + nc;
      gathered.resize(nb);
      for (int p = 0; p < nb; ++p) gathered[p] = x[rows[p]];
      dgemv_("T", &nb, &nc, &minus_one, block + nc, &nrows, gathered.data(), &one, &plus_one, x.data() + k1, &one);
    }
    dtrsv_("L", "T", "N", &nc, block, &nrows, x.data() + k1, &one);
  }
  return x;
}

Eigen::VectorXd DisplacementTrace::at(const Eigen::VectorXd& lambda) const {
  const Eigen::VectorXd x = back_substitute(lambda, needed_);
  Eigen::VectorXd out(dofs_.size());
  for (std::size_t k = 0; k < dofs_.size(); ++k) out[k] = x[position_[dofs_[k]]];
  return out;
}

Eigen::VectorXd DisplacementTrace::everywhere(const Eigen::VectorXd& lambda) const {
  const Eigen::VectorXd x = back_substitute(lambda, all_);
  Eigen::VectorXd out(n_);
  for (std::int64_t d = 0; d < n_; ++d) out[d] = x[position_[d]];
  return out;
}

}  // namespace contact3d
