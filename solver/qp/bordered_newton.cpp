#include "qp/bordered_newton.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <utility>

#include "base/memory.hpp"
#include "linalg/blas.hpp"

namespace contact3d {
namespace {

// The BLAS calls by precision (column-major, leading dimension m for the factor and the cache).
void forward(int m, const double* L, double* x) {
  const int one = 1;
  dtrsv_("L", "N", "N", &m, L, &m, x, &one);
}
void forward(int m, const float* L, float* x) {
  const int one = 1;
  strsv_("L", "N", "N", &m, L, &m, x, &one);
}
void backward(int m, const double* L, double* x) {
  const int one = 1;
  dtrsv_("L", "T", "N", &m, L, &m, x, &one);
}
void backward(int m, const float* L, float* x) {
  const int one = 1;
  strsv_("L", "T", "N", &m, L, &m, x, &one);
}
// B ← L⁻¹ B (trans "N") or L⁻ᵀ B ("T"), B: m × n.
void triangular_columns(const char* trans, int m, int n, const double* L, double* B) {
  const double one = 1;
  dtrsm_("L", "L", trans, "N", &m, &n, &one, L, &m, B, &m);
}
void triangular_columns(const char* trans, int m, int n, const float* L, float* B) {
  const float one = 1;
  strsm_("L", "L", trans, "N", &m, &n, &one, L, &m, B, &m);
}
// C (rows × cols, leading dimension ldc) = Aᵀ B, A: m × rows, B: m × cols.
void gram(int m, int rows, int cols, const double* A, const double* B, double* C, int ldc) {
  const double one = 1, zero = 0;
  dgemm_("T", "N", &rows, &cols, &m, &one, A, &m, B, &m, &zero, C, &ldc);
}
void gram(int m, int rows, int cols, const float* A, const float* B, float* C, int ldc) {
  const float one = 1, zero = 0;
  sgemm_("T", "N", &rows, &cols, &m, &one, A, &m, B, &m, &zero, C, &ldc);
}
// C = alpha A B + beta C, A: m × k (leading dimension m), B: k × n, C: m × n.
void product(int m, int n, int k, double alpha, const double* A, const double* B, double beta, double* C) {
  dgemm_("N", "N", &m, &n, &k, &alpha, A, &m, B, &k, &beta, C, &m);
}
void product(int m, int n, int k, float alpha, const float* A, const float* B, float beta, float* C) {
  sgemm_("N", "N", &m, &n, &k, &alpha, A, &m, B, &k, &beta, C, &m);
}
// y = alpha op(A) x + beta y, A: m × n.
void gemv(const char* trans, int m, int n, double alpha, const double* A, const double* x, double beta, double* y) {
  const int one = 1;
  dgemv_(trans, &m, &n, &alpha, A, &m, x, &one, &beta, y, &one);
}
void gemv(const char* trans, int m, int n, float alpha, const float* A, const float* x, float beta, float* y) {
  const int one = 1;
  sgemv_(trans, &m, &n, &alpha, A, &m, x, &one, &beta, y, &one);
}

// One column of the border U: w_a e_a + w_b e_b (b < 0: w_a e_a), with its entry of C.
struct Border {
  int a, b;
  double w_a, w_b, c;
};

template <typename T>
class BorderedNewtonWith final : public BorderedNewton {
  using Matrix = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<T, Eigen::Dynamic, 1>;

 public:
  BorderedNewtonWith(std::shared_ptr<const DualOperatorFactor> owner, const Matrix& L, const Eigen::VectorXd& scale)
      : owner_(std::move(owner)), L_(L), m_(static_cast<int>(L.rows())), slot_(static_cast<std::size_t>(m_), -1) {
    // Ŝ Q Ŝ = L̂ L̂ᵀ with L̂ = √scale_Q · S · L, so L̂⁻¹ v = L⁻¹ (unit_scale_ ⊙ v), L̂⁻ᵀ t = unit_scale_ ⊙ (L⁻ᵀ t).
    unit_scale_ = scale.cwiseInverse() / std::sqrt(owner_->scale);
  }

  bool prepare(const std::vector<Direction>& d) override {
    ++preparations_;
    if (!collect_borders(d)) return false;
    const std::vector<int> units = units_of_borders();
    int fresh = 0;
    for (int i : units) fresh += slot_[i] < 0;
    const bool restart = cached() + fresh > m_ / 2;  // the cache holds at most m/2 unit vectors
    if (restart) fresh = static_cast<int>(units.size());
    const double m = m_, p = static_cast<double>(borders_.size()), k = static_cast<double>(d.size());
    const double total = restart ? fresh : cached() + fresh;
    const double flops = m * m * fresh + 2.0 * m * total * fresh + p * p * p / 3.0;
    // Ski rental: the unit vectors cached now serve every later step whose border they cover, so
    // their fill is bought once the reduced factorizations it would have spared since the last fill
    // have cost as much as it does — never more than twice the cheaper choice in hindsight. (A fill
    // dearer than one reduced factorization, refused at every step, left a Coulomb gasket's first
    // frictional solve 18 factorizations of the free size 6 300.)
    const double reduced = k * k * k / 3.0;
    if (!(flops < reduced + reduced_flops_since_fill_)) {
      reduced_flops_since_fill_ += reduced;
      return false;
    }
    reduced_flops_since_fill_ = 0;
    if (restart) {
      std::fill(slot_.begin(), slot_.end(), -1);
      W_.resize(m_, 0);
      gram_.resize(0, 0);
    }
    add_units(units);
    if (!factor_border()) return false;
    directions_ = d;
    prepare_flops_ = flops;
    return true;
  }

  Eigen::VectorXd solve(const Eigen::VectorXd& b) const override {
    const Eigen::VectorXd u = prolong(directions_, b, m_).cwiseProduct(unit_scale_);
    const double size = u.cwiseAbs().maxCoeff();
    if (!(size > 0) || !std::isfinite(size)) return Eigen::VectorXd::Zero(b.size()) * size;
    Vector t = (u / size).template cast<T>();
    forward(m_, L_.data(), t.data());  // t = L̂⁻¹ D b
    const int n = cached();
    Vector wt = Vector::Zero(n);  // Wᵀ t
    if (n > 0) gemv("T", m_, n, T(1), W_.data(), t.data(), T(0), wt.data());
    Eigen::VectorXd rhs(static_cast<Eigen::Index>(borders_.size()));  // Uᵀ Q̂⁻¹ D b
    for (std::size_t j = 0; j < borders_.size(); ++j) {
      const Border& e = borders_[j];
      rhs[static_cast<Eigen::Index>(j)] =
          e.w_a * wt[slot_[e.a]] + (e.b >= 0 ? e.w_b * static_cast<double>(wt[slot_[e.b]]) : 0.0);
    }
    const Eigen::VectorXd v = border_factor_ ? border_factor_->solve(rhs) : rhs;
    Vector z = Vector::Zero(n);  // U v in the cached unit vectors
    for (std::size_t j = 0; j < borders_.size(); ++j) {
      const Border& e = borders_[j];
      z[slot_[e.a]] += static_cast<T>(e.w_a * v[static_cast<Eigen::Index>(j)]);
      if (e.b >= 0) z[slot_[e.b]] += static_cast<T>(e.w_b * v[static_cast<Eigen::Index>(j)]);
    }
    if (n > 0) gemv("N", m_, n, T(-1), W_.data(), z.data(), T(1), t.data());  // L̂⁻¹ (D b − U v)
    backward(m_, L_.data(), t.data());
    const Eigen::VectorXd x = t.template cast<double>().cwiseProduct(unit_scale_) * size;
    return restrict_to(directions_, x);
  }

  // solve() with matrices: each column scaled to unit max-norm (no under- or overflow in single).
  Eigen::MatrixXd solve_columns(const Eigen::MatrixXd& B) const override {
    const Eigen::MatrixXd U = unit_scale_.asDiagonal() * prolong(directions_, B, m_);
    const auto k = static_cast<int>(B.cols());
    Eigen::VectorXd size = U.cwiseAbs().colwise().maxCoeff().transpose();
    if (k == 0 || !size.allFinite()) return Eigen::MatrixXd::Zero(B.rows(), k) * size.sum();
    size = (size.array() > 0).select(size, 1.0);
    Matrix X = (U * size.cwiseInverse().asDiagonal()).template cast<T>();
    triangular_columns("N", m_, k, L_.data(), X.data());  // L̂⁻¹ D B
    const int n = cached();
    if (n > 0) {
      Matrix WX(n, k);  // Wᵀ L̂⁻¹ D B
      gram(m_, n, k, W_.data(), X.data(), WX.data(), n);
      Eigen::MatrixXd rhs(static_cast<Eigen::Index>(borders_.size()), k);  // Uᵀ Q̂⁻¹ D B
      for (std::size_t j = 0; j < borders_.size(); ++j) {
        const Border& e = borders_[j];
        rhs.row(static_cast<Eigen::Index>(j)) = e.w_a * WX.row(slot_[e.a]).template cast<double>();
        if (e.b >= 0) rhs.row(static_cast<Eigen::Index>(j)) += e.w_b * WX.row(slot_[e.b]).template cast<double>();
      }
      const Eigen::MatrixXd V = border_factor_ ? border_factor_->solve_columns(rhs) : rhs;
      Matrix Z = Matrix::Zero(n, k);  // U V in the cached unit vectors
      for (std::size_t j = 0; j < borders_.size(); ++j) {
        const Border& e = borders_[j];
        Z.row(slot_[e.a]) += (e.w_a * V.row(static_cast<Eigen::Index>(j))).template cast<T>();
        if (e.b >= 0) Z.row(slot_[e.b]) += (e.w_b * V.row(static_cast<Eigen::Index>(j))).template cast<T>();
      }
      product(m_, k, n, T(-1), W_.data(), Z.data(), T(1), X.data());  // L̂⁻¹ (D B − U V)
    }
    triangular_columns("T", m_, k, L_.data(), X.data());
    return restrict_columns(directions_,
                            Eigen::MatrixXd(unit_scale_.asDiagonal() * X.template cast<double>() * size.asDiagonal()));
  }

  double prepare_flops() const override { return prepare_flops_; }
  int cached_units() const override { return cached(); }
  long preparations() const override { return preparations_; }
  bool exact() const override { return std::is_same_v<T, double>; }

 private:
  int cached() const { return static_cast<int>(W_.cols()); }

  // U = [N T]: the complement of the directions (unit vectors they leave out; in a pair of
  // indices the unit vector orthogonal to the direction) and the directions with a shift. False
  // when the directions are not orthonormal unit or pair vectors on disjoint indices.
  bool collect_borders(const std::vector<Direction>& d) {
    borders_.clear();
    std::vector<char> covered(static_cast<std::size_t>(m_), 0);
    for (const Direction& e : d) {
      if (e.a < 0 || e.a >= m_ || e.b >= m_ || covered[e.a] || (e.b >= 0 && covered[e.b])) return false;
      covered[e.a] = 1;
      if (e.b >= 0) {
        covered[e.b] = 1;
        if (std::abs(e.w_a * e.w_a + e.w_b * e.w_b - 1) > 1e-12) return false;
        borders_.push_back({e.a, e.b, e.w_b, -e.w_a, 0.0});
      } else if (std::abs(e.w_a) != 1) {
        return false;
      }
      if (e.shift > 0) borders_.push_back({e.a, e.b, e.w_a, e.w_b, 1.0 / e.shift});
    }
    for (int i = 0; i < m_; ++i)
      if (!covered[i]) borders_.push_back({i, -1, 1.0, 0.0, 0.0});
    return true;
  }

  std::vector<int> units_of_borders() const {
    std::vector<int> units;
    std::vector<char> seen(static_cast<std::size_t>(m_), 0);
    for (const Border& e : borders_)
      for (int i : {e.a, e.b})
        if (i >= 0 && !seen[i]) {
          seen[i] = 1;
          units.push_back(i);
        }
    return units;
  }

  // W = L̂⁻¹ e_i for the unit vectors not yet cached, and their rows and columns of the Gram matrix.
  void add_units(const std::vector<int>& units) {
    std::vector<int> fresh;
    for (int i : units)
      if (slot_[i] < 0) fresh.push_back(i);
    if (fresh.empty()) return;
    const int before = cached(), added = static_cast<int>(fresh.size()), after = before + added;
    W_.conservativeResize(m_, after);
    W_.rightCols(added).setZero();
    for (int j = 0; j < added; ++j) {
      W_(fresh[j], before + j) = static_cast<T>(unit_scale_[fresh[j]]);
      slot_[fresh[j]] = before + j;
    }
    triangular_columns("N", m_, added, L_.data(), W_.data() + static_cast<std::ptrdiff_t>(before) * m_);
    gram_.conservativeResize(after, after);
    gram(m_, after, added, W_.data(), W_.data() + static_cast<std::ptrdiff_t>(before) * m_,
         gram_.data() + static_cast<std::ptrdiff_t>(before) * after, after);
    gram_.block(before, 0, added, before) = gram_.block(0, before, before, added).transpose();
  }

  // Uᵀ Q̂⁻¹ U + C from the Gram matrix of the unit vectors, factored.
  bool factor_border() {
    const auto p = static_cast<Eigen::Index>(borders_.size());
    border_factor_.reset();
    if (p == 0) return true;
    Eigen::MatrixXd G(p, p);
    for (Eigen::Index j = 0; j < p; ++j) {
      const Border& c = borders_[static_cast<std::size_t>(j)];
      const int ca = slot_[c.a], cb = c.b >= 0 ? slot_[c.b] : -1;
      for (Eigen::Index i = j; i < p; ++i) {
        const Border& e = borders_[static_cast<std::size_t>(i)];
        const int ea = slot_[e.a], eb = e.b >= 0 ? slot_[e.b] : -1;
        double g = c.w_a * e.w_a * gram_(ea, ca);
        if (eb >= 0) g += c.w_a * e.w_b * gram_(eb, ca);
        if (cb >= 0) {
          g += c.w_b * e.w_a * gram_(ea, cb);
          if (eb >= 0) g += c.w_b * e.w_b * gram_(eb, cb);
        }
        G(i, j) = i == j ? g + c.c : g;
      }
    }
    border_factor_.emplace(std::move(G));
    return border_factor_->ok();
  }

  std::shared_ptr<const DualOperatorFactor> owner_;
  const Matrix& L_;
  int m_;
  Eigen::VectorXd unit_scale_;
  std::vector<int> slot_;  // unit index → its column of W_ and row of gram_ (−1: not cached)
  Matrix W_;               // L̂⁻¹ e_i, one column per cached unit vector
  Matrix gram_;            // W_ᵀ W_ = (Q̂⁻¹) on the cached indices
  std::vector<Border> borders_;
  std::vector<Direction> directions_;
  std::optional<DenseCholesky> border_factor_;
  double prepare_flops_ = 0;
  long preparations_ = 0;
  double reduced_flops_since_fill_ = 0;  // the refused steps' reduced factorizations since the last fill
};

// Products by Q a refinement of a good single factor takes (the first residual and one correction,
// cond(Q)·ε_single ≲ 1e-5). Each one beyond it is charged to the single factor, priced together with
// the approximate solve that comes with it (two triangular solves with the single factor, single-
// threaded in OpenBLAS, and two products with the cache): 8.8 ms against 1.7 ms for a product on the
// free thin slab at m = 4 800 (2 BLAS threads), which a factor in double spares.
constexpr int kProductsOfAGoodRefinement = 2;
constexpr double kRefinementStepInProducts = 5;
// dpotrf's and dtrsm's flop rate over a product's (dsymv: memory-bound), measured at m = 4 800 on
// the 2-core machine: 2.8 on two BLAS threads (0.48 s for m³/3 flops, 1.7 ms for 2m²), 3.7 on one.
constexpr double kFactorOverProductRate = 3;

// The bordered solver on a single factor of Q that switches, once, to a factor of Q in double: when
// the products its refinements took beyond kProductsOfAGoodRefinement have cost as much as factoring Q
// in double and filling that factor's cache again (priced in products), and the memory for both is
// there. Holders of a prepared system see preparations() move on at the switch and prepare again.
class SwitchingBorderedNewton final : public BorderedNewton {
 public:
  SwitchingBorderedNewton(std::unique_ptr<BorderedNewton> single, DenseViewPtr Q, Eigen::VectorXd scale)
      : current_(std::move(single)), Q_(Q), scale_(std::move(scale)) {}

  bool prepare(const std::vector<Direction>& d) override {
    ++preparations_;
    if (!current_->prepare(d)) return false;
    prepare_flops_ = current_->prepare_flops();
    return true;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const override { return current_->solve(b); }
  Eigen::MatrixXd solve_columns(const Eigen::MatrixXd& B) const override { return current_->solve_columns(B); }
  double prepare_flops() const override { return prepare_flops_; }
  // Refined by the caller also after the switch (one or two products, cond(Q)·ε_double): the
  // equality loop's inner solves ask for 1e-12, which a solve in double with cond(Q) = 6e6 misses
  // (the free slab at 2 523 multipliers: its Newton steps stalled, MPGP took 15 900 iterations).
  bool exact() const override { return false; }
  int cached_units() const override { return current_->cached_units(); }
  long preparations() const override { return preparations_; }
  bool switched_to_double() const override { return current_->exact(); }  // the single factor's is not

  void record_refinement(int products) override {
    if (tried_) return;
    excess_products_ += kRefinementStepInProducts * std::max(0, products - kProductsOfAGoodRefinement);
    const double m = static_cast<double>(scale_.size()), cached = current_->cached_units();
    // Factoring Q in double (m³/3 flops) and caching L⁻¹e_i again for as many unit vectors (m² each).
    const double switch_in_products = (m / 3.0 + cached) / (2.0 * kFactorOverProductRate);
    if (excess_products_ >= switch_in_products) switch_to_double(m, cached);
  }

 private:
  void switch_to_double(double m, double cached) {
    tried_ = true;
    const double bytes = sizeof(double) * m * (m + cached);
    const double available = static_cast<double>(available_memory_bytes());
    if (available > 0 && bytes > 0.5 * available) return;
    auto factor = std::make_shared<DualOperatorFactor>();
    factor->in_double.emplace(Eigen::MatrixXd(*Q_));
    if (!factor->in_double->ok()) return;
    current_ = std::make_unique<BorderedNewtonWith<double>>(factor, factor->in_double->lower(), scale_);
    ++preparations_;  // the system prepared on the single factor is gone
  }

  std::unique_ptr<BorderedNewton> current_;
  DenseViewPtr Q_;
  Eigen::VectorXd scale_;
  double prepare_flops_ = 0;
  long preparations_ = 0;
  double excess_products_ = 0;  // charged to the single factor so far, in products by Q
  bool tried_ = false;          // the switch, taken or refused (memory, a failed factorization), is tried once
};

}  // namespace

std::unique_ptr<BorderedNewton> make_bordered_newton(std::shared_ptr<const DualOperatorFactor> factor,
                                                     const Eigen::VectorXd& scale, DenseViewPtr Q) {
  if (!factor || !(factor->scale > 0) || !(scale.array() > 0).all()) return nullptr;
  if (factor->in_double && factor->in_double->ok() && factor->in_double->lower().rows() == scale.size())
    return std::make_unique<BorderedNewtonWith<double>>(factor, factor->in_double->lower(), scale);
  if (!factor->in_single || !factor->in_single->ok() || factor->in_single->lower().rows() != scale.size())
    return nullptr;
  auto single = std::make_unique<BorderedNewtonWith<float>>(factor, factor->in_single->lower(), scale);
  if (!Q || (*Q).rows() != scale.size()) return single;
  return std::make_unique<SwitchingBorderedNewton>(std::move(single), Q, scale);
}

}  // namespace contact3d
