#include "linalg/dual_problem.hpp"

#include <algorithm>
#include <optional>
#include <stdexcept>

#include "base/memory.hpp"
#include "linalg/displacement_trace.hpp"
#include "linalg/dual_operator.hpp"
#include "linalg/single_precision_factor.hpp"
#include "linalg/sparse_cholesky.hpp"
#include "linalg/sparse_forward_solve.hpp"

namespace contact3d {
namespace {

// One CHOLMOD factor, whichever way it was built; w by a full solve, or for the augmented factor
// by the restricted back substitution of DisplacementTrace.
class CholmodDualProblem final : public DualProblem {
 public:
  CholmodDualProblem(DualMethod m, const DualProblemInput& in, StageClock& clock) : B_(in.B), face_dofs_(in.face_dofs) {
    if (in.B.rows() == 0) m = DualMethod::BlockSolve;  // nothing to form: a plain factor of K
    if (m == DualMethod::Auto) m = DualMethod::Augmented;
    method = m == DualMethod::Augmented ? "augmented" : m == DualMethod::ContactLast ? "contactlast" : "blocksolve";
    factor_ = m == DualMethod::ContactLast ? std::make_shared<SparseCholesky>(in.K, contact_dofs(in.B), in.on_analysis)
              : m == DualMethod::Augmented
                  ? std::make_shared<SparseCholesky>(in.K, in.B, 0.0, in.on_analysis)
                  : std::make_shared<SparseCholesky>(in.K, FillOrdering::QuotientNestedDissection, in.on_analysis);
    factor_nonzeros = factor_->factor_nonzeros();
    clock.lap("factorization");

    DualOperator dual;
    if (m == DualMethod::Augmented) {
      trace_.emplace(*factor_, in.f, face_dofs_);
      step_solve_fraction = trace_->work_fraction();
      const Eigen::VectorXd u_free = trace_->everywhere(Eigen::VectorXd::Zero(in.B.rows()));
      dual = make_dual_operator_augmented(*factor_, in.B, in.f, &u_free);
    } else if (m == DualMethod::ContactLast) {
      dual = make_dual_operator_schur(*factor_, in.B, in.f);
    } else {
      dual = make_dual_operator(*factor_, in.B, in.f);
    }
    Q_ = std::move(dual.Q);
    Q_in_factor_ = dual.Q_in_factor;
    h_ = std::move(dual.h);
    if (in.offset.size() == h_.size()) h_ += in.offset;
    u_free_ = std::move(dual.u_free);
    clock.lap("dual");
  }

  Eigen::VectorXd face_displacement(const Eigen::VectorXd& lambda) const override {
    if (trace_) return trace_->at(lambda);
    return gather(displacement(lambda), face_dofs_);
  }

  Eigen::VectorXd displacement(const Eigen::VectorXd& lambda) const override {
    if (!factor_) throw std::logic_error("DualProblem: the factor was released");
    if (trace_) return trace_->everywhere(lambda);
    if (lambda.size() == 0) return u_free_;
    return u_free_ - factor_->solve(Eigen::VectorXd(B_.transpose() * lambda));
  }

  std::shared_ptr<const SparseCholesky> factor_to_share() const override {
    return factor_ && factor_->augmented() ? factor_ : nullptr;
  }

  void release_factor() override {
    Q_in_factor_ = nullptr;
    trace_.reset();  // it points into the factor
    factor_.reset();
  }

 private:
  const Eigen::SparseMatrix<double>& B_;
  std::vector<int> face_dofs_;
  std::shared_ptr<SparseCholesky> factor_;
  std::optional<DisplacementTrace> trace_;
  Eigen::VectorXd u_free_;  // K⁻¹f
};

// Q never formed (DualMethod::MatrixFree): the factor of K alone; Q's diagonal (for the Jacobi
// scaling) and W = L⁻¹P𝔹ᵀ by forward solves; each product Wᵀ(Wv) where W is kept, else 𝔹K⁻¹(𝔹ᵀv)
// by one full solve; each displacement by one full solve.
class MatrixFreeDualProblem final : public DualProblem {
 public:
  MatrixFreeDualProblem(const DualProblemInput& in, StageClock& clock) : B_(in.B), face_dofs_(in.face_dofs) {
    method = "matrix_free";
    factor_ = std::make_unique<SparseCholesky>(in.K, FillOrdering::QuotientNestedDissection, in.on_analysis);
    factor_nonzeros = factor_->factor_nonzeros();
    clock.lap("factorization");
    u_free_ = factor_->solve(in.f);
    h_ = B_ * u_free_;
    if (in.offset.size() == h_.size()) h_ += in.offset;
    // W = L⁻¹P𝔹ᵀ is kept for the products where its supernodal blocks hold under half the factor's
    // entries (a product Wᵀ(Wv), two dgemv per block, reads 8 bytes per entry twice, as a supernodal
    // solve does for the whole factor) and a quarter of the memory available at most; on a thin slab
    // W reaches most of the factor and it is not: the diagonal is then streamed in column blocks.
    const double memory_cap = 0.25 * static_cast<double>(available_memory_bytes()) / 8.0;
    const double cap = memory_cap > 0 ? std::min(0.5 * factor_nonzeros, memory_cap) : 0.5 * factor_nonzeros;
    const Eigen::SparseMatrix<double> Bt = B_.transpose();
    if (static_cast<double>(forward_solved_block_entries(*factor_, Bt)) <= cap) {
      forward_solved_ = forward_solve_by_supernodes(*factor_, Bt);
      diagonal_ = forward_solved_->column_squared_norms();
    } else {
      diagonal_ = forward_solved_diagonal(*factor_, B_);
    }
    clock.lap("dual");
  }

  Eigen::VectorXd apply_Q(const Eigen::VectorXd& v) const override {
    if (forward_solved_) return forward_solved_->gram_product(v);
    return B_ * solve(Eigen::VectorXd(B_.transpose() * v));
  }
  Eigen::VectorXd Q_diagonal() const override { return diagonal_; }
  bool blocks_pay() const override { return !forward_solved_; }  // Wᵀ(WV) costs per column what Wᵀ(Wv) does
  Eigen::MatrixXd apply_Q_block(const Eigen::MatrixXd& V) const override {
    if (forward_solved_) return forward_solved_->gram_product(V);
    return in_blocks(V, [this](const Eigen::MatrixXd& rhs) { return solve(rhs); });
  }
  Eigen::MatrixXd apply_Q_block_single(const Eigen::MatrixXd& V) const override {
    if (!single_) return apply_Q_block(V);
    return in_blocks(V, [this](const Eigen::MatrixXd& rhs) { return single_->solve(rhs); });
  }

  Eigen::VectorXd apply_Q_single(const Eigen::VectorXd& v) const override {
    if (!single_) return apply_Q(v);
    return B_ * single_->solve(Eigen::VectorXd(B_.transpose() * v));
  }
  bool prepare_single_products(double memory_bytes) override {
    // Where W is kept its products already read less than a solve does.
    if (!factor_ || forward_solved_) return false;
    if (SinglePrecisionFactor::bytes_for(*factor_) > memory_bytes) return false;
    single_ = std::make_unique<SinglePrecisionFactor>(*factor_);
    return true;
  }

  Eigen::VectorXd face_displacement(const Eigen::VectorXd& lambda) const override {
    return gather(displacement(lambda), face_dofs_);
  }
  Eigen::VectorXd displacement(const Eigen::VectorXd& lambda) const override {
    return u_free_ - solve(Eigen::VectorXd(B_.transpose() * lambda));
  }
  void release_factor() override {
    single_.reset();  // it reads the factor's structure
    factor_.reset();
  }

 private:
  // 𝔹 K⁻¹ 𝔹ᵀ V by `solve_block` in blocks of about 32 MiB of right-hand sides (each lives in a few
  // copies through the solve).
  template <typename BlockSolve>
  Eigen::MatrixXd in_blocks(const Eigen::MatrixXd& V, const BlockSolve& solve_block) const {
    const Eigen::Index step = block_columns_for(B_.cols(), static_cast<int>(V.cols()), 32LL << 20);
    Eigen::MatrixXd out(V.rows(), V.cols());
    for (Eigen::Index j = 0; j < V.cols(); j += step) {
      const Eigen::Index cols = std::min(step, V.cols() - j);
      out.middleCols(j, cols) = B_ * solve_block(Eigen::MatrixXd(B_.transpose() * V.middleCols(j, cols)));
    }
    return out;
  }
  template <typename Rhs>
  Rhs solve(const Rhs& b) const {  // one right-hand side or a block
    if (!factor_) throw std::logic_error("DualProblem: the factor was released");
    return factor_->solve(b);
  }

  const Eigen::SparseMatrix<double>& B_;
  std::vector<int> face_dofs_;
  std::unique_ptr<SparseCholesky> factor_;
  std::unique_ptr<SinglePrecisionFactor> single_;      // for apply_Q_single, or none
  Eigen::VectorXd u_free_;                             // K⁻¹f
  Eigen::VectorXd diagonal_;                           // Q's
  std::optional<ForwardSolvedBlocks> forward_solved_;  // W = L⁻¹P𝔹ᵀ (Q = WᵀW), or none: products by solves
};

// The dual problem of another 𝔹 on a factor of K already made (make_dual_problem_on_factor).
class SharedFactorDualProblem final : public DualProblem {
 public:
  SharedFactorDualProblem(std::shared_ptr<const SparseCholesky> factor, const DualProblemInput& in, StageClock& clock)
      : factor_(std::move(factor)) {
    method = "augmented";
    factor_nonzeros = factor_->factor_nonzeros();
    clock.lap("factorization");
    W_ = forward_solve_by_supernodes(*factor_, Eigen::SparseMatrix<double>(in.B.transpose()));
    Q_ = W_.gram();
    trace_.emplace(*factor_, in.f, in.face_dofs, W_);
    step_solve_fraction = trace_->work_fraction();
    u_free_ = trace_->everywhere(Eigen::VectorXd::Zero(in.B.rows()));
    h_ = in.B * u_free_;
    if (in.offset.size() == h_.size()) h_ += in.offset;
    clock.lap("dual");
  }

  Eigen::VectorXd face_displacement(const Eigen::VectorXd& lambda) const override {
    if (!trace_) throw std::logic_error("DualProblem: the factor was released");
    return trace_->at(lambda);
  }
  Eigen::VectorXd displacement(const Eigen::VectorXd& lambda) const override {
    if (!trace_) throw std::logic_error("DualProblem: the factor was released");
    if (lambda.size() == 0) return u_free_;
    return trace_->everywhere(lambda);
  }
  void release_factor() override {
    trace_.reset();
    factor_.reset();
  }

 private:
  std::shared_ptr<const SparseCholesky> factor_;
  ForwardSolvedBlocks W_;  // L₁₁⁻¹P𝔹ᵀ by supernodes (before trace_, which reads it)
  std::optional<DisplacementTrace> trace_;
  Eigen::VectorXd u_free_;  // K⁻¹f
};

}  // namespace

AugmentedFactorParts augmented_factor_parts(const SparseCholesky& factor) {
  AugmentedFactorParts parts;
  const SparseCholesky::Supernodes L = factor.supernodes();
  const std::int64_t n = factor.size();
  for (std::int64_t s = 0; s < L.count && L.super[s] < n; ++s) {
    const std::int64_t columns = std::min(L.super[s + 1], n) - L.super[s];
    const std::int64_t* rows = L.rows + L.pi[s];
    const std::int64_t count = L.pi[s + 1] - L.pi[s];
    // K's rows first (its own columns, then the rows below ascending), the multipliers' last.
    const std::int64_t leading_rows = std::lower_bound(rows + columns, rows + count, n) - rows;
    parts.leading += double(columns) * double(leading_rows);
    parts.coupling += double(columns) * double(count - leading_rows);
  }
  return parts;
}

std::unique_ptr<DualProblem> make_dual_problem_on_factor(std::shared_ptr<const SparseCholesky> factor,
                                                         const DualProblemInput& input, StageClock& clock) {
  return std::make_unique<SharedFactorDualProblem>(std::move(factor), input, clock);
}

std::unique_ptr<DualProblem> make_cholmod_dual_problem(DualMethod method, const DualProblemInput& input,
                                                       StageClock& clock) {
  if (method == DualMethod::MatrixFree && input.B.rows() > 0)
    return std::make_unique<MatrixFreeDualProblem>(input, clock);
  return std::make_unique<CholmodDualProblem>(method, input, clock);
}

}  // namespace contact3d
