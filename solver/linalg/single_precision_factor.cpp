#include "linalg/single_precision_factor.hpp"

#include <algorithm>
#include <stdexcept>

#include "linalg/blas.hpp"

namespace contact3d {
namespace {

// Supernodes of at most this many entries take plain loops for one right-hand side, larger ones
// BLAS (strsv/sgemv, on its threads). Slab, h = 0.0175, 5-product means: BLAS alone 39 ms, loops
// alone 57 ms, loops up to 4 096 or 16 384 entries 37 ms, up to 65 536: 49 ms.
constexpr std::int64_t kLoopEntries = 4096;

std::int64_t value_count(const SparseCholesky::Supernodes& L) { return L.count > 0 ? L.px[L.count] : 0; }

// One right-hand side through supernode `block` (nrows × nc, column-major, lda nrows): the diagonal
// block's forward substitution on x (contiguous, nc entries), accumulating the rows below into
// `below` (nrows − nc entries, zeroed here). Plain loops: a single vector's solve reads every entry
// of the factor once, and BLAS-2 calls on the many small supernodes cost more in calls and thread
// hand-offs than the loops do.
void forward_one(const float* block, int nrows, int nc, float* x, float* below) {
  const int nb = nrows - nc;
  for (int p = 0; p < nb; ++p) below[p] = 0;
  for (int j = 0; j < nc; ++j) {
    const float* column = block + static_cast<std::int64_t>(j) * nrows;
    const float xj = x[j] / column[j];
    x[j] = xj;
    for (int i = j + 1; i < nc; ++i) x[i] -= column[i] * xj;
    const float* lower = column + nc;
    for (int p = 0; p < nb; ++p) below[p] += lower[p] * xj;
  }
}

// Σ a_i b_i in four interleaved sums (so that the compiler may vectorize it without reassociating).
float dot(const float* a, const float* b, int n) {
  float s0 = 0, s1 = 0, s2 = 0, s3 = 0;
  int i = 0;
  for (; i + 4 <= n; i += 4) {
    s0 += a[i] * b[i];
    s1 += a[i + 1] * b[i + 1];
    s2 += a[i + 2] * b[i + 2];
    s3 += a[i + 3] * b[i + 3];
  }
  for (; i < n; ++i) s0 += a[i] * b[i];
  return (s0 + s1) + (s2 + s3);
}

// The transpose: x ← L_ssᵀ⁻¹ (x − L_bsᵀ gathered), `gathered` the solved rows below.
void backward_one(const float* block, int nrows, int nc, float* x, const float* gathered) {
  const int nb = nrows - nc;
  for (int j = nc - 1; j >= 0; --j) {
    const float* column = block + static_cast<std::int64_t>(j) * nrows;
    const float s = x[j] - dot(column + j + 1, x + j + 1, nc - j - 1) - dot(column + nc, gathered, nb);
    x[j] = s / column[j];
  }
}

}  // namespace

SinglePrecisionFactor::SinglePrecisionFactor(const SparseCholesky& factor) : L_(factor.supernodes()) {
  if (factor.augmented()) throw std::logic_error("SinglePrecisionFactor needs the factor of K alone");
  values_.resize(static_cast<std::size_t>(value_count(L_)));
  std::transform(L_.values, L_.values + values_.size(), values_.begin(),
                 [](double x) { return static_cast<float>(x); });
}

double SinglePrecisionFactor::bytes_for(const SparseCholesky& factor) {
  return 4.0 * static_cast<double>(value_count(factor.supernodes()));
}

SinglePrecisionFactor::Supernode SinglePrecisionFactor::supernode(std::int64_t s) const {
  Supernode v;
  v.first_column = L_.super[s];
  v.columns = static_cast<int>(L_.super[s + 1] - v.first_column);
  v.rows = static_cast<int>(L_.pi[s + 1] - L_.pi[s]);
  v.values = values_.data() + L_.px[s];
  v.rows_below = L_.rows + L_.pi[s] + v.columns;
  return v;
}

// X_s ← L_ss⁻¹ X_s, then the rows below the supernode lose L_bs X_s.
void SinglePrecisionFactor::forward_step(const Supernode& s, float* X, int k, std::vector<float>& below) const {
  const int nc = s.columns, nrows = s.rows, nb = s.rows - s.columns, ldx = static_cast<int>(L_.n), one = 1;
  const float zero = 0, plus_one = 1;
  float* Xs = X + s.first_column;
  below.resize(static_cast<std::size_t>(nb) * k);
  if (k == 1 && static_cast<std::int64_t>(nrows) * nc <= kLoopEntries) {
    forward_one(s.values, nrows, nc, Xs, below.data());
  } else if (k == 1) {
    strsv_("L", "N", "N", &nc, s.values, &nrows, Xs, &one);
    if (nb > 0) sgemv_("N", &nb, &nc, &plus_one, s.values + nc, &nrows, Xs, &one, &zero, below.data(), &one);
  } else {
    strsm_("L", "L", "N", "N", &nc, &k, &plus_one, s.values, &nrows, Xs, &ldx);
    if (nb > 0) sgemm_("N", "N", &nb, &k, &nc, &plus_one, s.values + nc, &nrows, Xs, &ldx, &zero, below.data(), &nb);
  }
  for (int c = 0; c < k; ++c) {
    float* x = X + static_cast<std::int64_t>(c) * L_.n;
    const float* t = below.data() + static_cast<std::int64_t>(c) * nb;
    for (int p = 0; p < nb; ++p) x[s.rows_below[p]] -= t[p];
  }
}

// X_s ← L_ssᵀ⁻¹ (X_s − L_bsᵀ X_b), the rows below already solved.
void SinglePrecisionFactor::backward_step(const Supernode& s, float* X, int k, std::vector<float>& below) const {
  const int nc = s.columns, nrows = s.rows, nb = s.rows - s.columns, ldx = static_cast<int>(L_.n), one = 1;
  const float plus_one = 1, minus_one = -1;
  float* Xs = X + s.first_column;
  below.resize(static_cast<std::size_t>(nb) * k);
  for (int c = 0; c < k; ++c) {
    const float* x = X + static_cast<std::int64_t>(c) * L_.n;
    float* t = below.data() + static_cast<std::int64_t>(c) * nb;
    for (int p = 0; p < nb; ++p) t[p] = x[s.rows_below[p]];
  }
  if (k == 1 && static_cast<std::int64_t>(nrows) * nc <= kLoopEntries) {
    backward_one(s.values, nrows, nc, Xs, below.data());
  } else if (k == 1) {
    if (nb > 0) sgemv_("T", &nb, &nc, &minus_one, s.values + nc, &nrows, below.data(), &one, &plus_one, Xs, &one);
    strsv_("L", "T", "N", &nc, s.values, &nrows, Xs, &one);
  } else {
    if (nb > 0)
      sgemm_("T", "N", &nc, &k, &nb, &minus_one, s.values + nc, &nrows, below.data(), &nb, &plus_one, Xs, &ldx);
    strsm_("L", "L", "T", "N", &nc, &k, &plus_one, s.values, &nrows, Xs, &ldx);
  }
}

void SinglePrecisionFactor::solve_in_pivot_order(float* X, int k) const {
  std::vector<float> below;
  for (std::int64_t s = 0; s < L_.count; ++s) forward_step(supernode(s), X, k, below);
  // Descending: every row below a supernode is solved before it.
  for (std::int64_t s = L_.count - 1; s >= 0; --s) backward_step(supernode(s), X, k, below);
}

Eigen::MatrixXd SinglePrecisionFactor::solve(const Eigen::MatrixXd& B) const {
  if (B.rows() != L_.n) throw std::invalid_argument("SinglePrecisionFactor: right-hand side of the wrong size");
  const int k = static_cast<int>(B.cols());
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(B.rows(), B.cols());
  if (k == 0 || L_.n == 0) return out;
  // Each column scaled to unit max-norm, then permuted into pivot order: X_kc = B_perm[k],c / scale_c.
  Eigen::VectorXd column_scale = B.cwiseAbs().colwise().maxCoeff().transpose();
  Eigen::MatrixXf X(B.rows(), B.cols());
  for (int c = 0; c < k; ++c) {
    const double inverse = column_scale[c] > 0 ? 1.0 / column_scale[c] : 0.0;
    for (std::int64_t p = 0; p < L_.n; ++p) X(p, c) = static_cast<float>(B(L_.perm[p], c) * inverse);
  }
  solve_in_pivot_order(X.data(), k);
  for (int c = 0; c < k; ++c)
    for (std::int64_t p = 0; p < L_.n; ++p) out(L_.perm[p], c) = column_scale[c] * static_cast<double>(X(p, c));
  return out;
}

Eigen::VectorXd SinglePrecisionFactor::solve(const Eigen::VectorXd& b) const {
  return solve(Eigen::MatrixXd(b)).col(0);
}

}  // namespace contact3d
