#include "linalg/sparse_cholesky.hpp"

#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

#include <cholmod.h>

namespace contact3d {

struct SparseCholesky::Impl {
  cholmod_common common;
  cholmod_factor* factor = nullptr;
  std::vector<SuiteSparse_long> col_ptr, row_idx;
  std::vector<double> values;
};

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

SparseCholesky::SparseCholesky(const Eigen::SparseMatrix<double>& K) : impl_(new Impl), n_(static_cast<int>(K.rows())) {
  cholmod_common* c = &impl_->common;
  cholmod_l_start(c);
  c->supernodal = CHOLMOD_SUPERNODAL;
  c->final_ll = 1;
  c->print = 0;
  // Upper triangle of K in CSC with 64-bit indices (nnz(L) can pass 2^31 on big meshes).
  const int n = n_;
  impl_->col_ptr.assign(n + 1, 0);
  for (int j = 0; j < n; ++j) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, j); it; ++it)
      if (it.row() <= j) {
        impl_->row_idx.push_back(it.row());
        impl_->values.push_back(it.value());
      }
    impl_->col_ptr[j + 1] = static_cast<SuiteSparse_long>(impl_->row_idx.size());
  }
  cholmod_sparse A{};
  A.nrow = A.ncol = n;
  A.nzmax = impl_->values.size();
  A.p = impl_->col_ptr.data();
  A.i = impl_->row_idx.data();
  A.x = impl_->values.data();
  A.stype = 1;
  A.itype = CHOLMOD_LONG;
  A.xtype = CHOLMOD_REAL;
  A.dtype = CHOLMOD_DOUBLE;
  A.sorted = 1;
  A.packed = 1;
  auto t0 = std::chrono::steady_clock::now();
  impl_->factor = cholmod_l_analyze(&A, c);
  analyze_seconds = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  if (impl_->factor) cholmod_l_factorize(&A, impl_->factor, c);
  factorize_seconds = seconds_since(t0);
  // The factor keeps no pointer to A; free the copy.
  impl_->col_ptr = {}; impl_->row_idx = {}; impl_->values = {};
  if (!impl_->factor || c->status == CHOLMOD_NOT_POSDEF || c->status < 0) {
    const std::string why = c->status == CHOLMOD_NOT_POSDEF
                                ? "the stiffness matrix is not positive definite (column " +
                                      std::to_string(impl_->factor ? impl_->factor->minor : -1) +
                                      "): the clamped part Γu must prevent rigid motions"
                                : "CHOLMOD failed (status " + std::to_string(c->status) + ", out of memory?)";
    if (impl_->factor) cholmod_l_free_factor(&impl_->factor, c);
    cholmod_l_finish(c);
    delete impl_;
    throw std::runtime_error(why);
  }
}

SparseCholesky::~SparseCholesky() {
  cholmod_l_free_factor(&impl_->factor, &impl_->common);
  cholmod_l_finish(&impl_->common);
  delete impl_;
}

double SparseCholesky::factor_nonzeros() const {
  const cholmod_factor* L = impl_->factor;
  if (L->is_super) {
    double nnz = 0;
    const auto* super = static_cast<const SuiteSparse_long*>(L->super);
    const auto* pi = static_cast<const SuiteSparse_long*>(L->pi);
    for (std::size_t s = 0; s < L->nsuper; ++s) {
      const double ncols = double(super[s + 1] - super[s]), nrows = double(pi[s + 1] - pi[s]);
      nnz += ncols * nrows - ncols * (ncols - 1) / 2;
    }
    return nnz;
  }
  return double(impl_->common.lnz);
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& B) const {
  cholmod_common* c = &impl_->common;
  cholmod_dense rhs{};
  rhs.nrow = B.rows();
  rhs.ncol = B.cols();
  rhs.nzmax = B.size();
  rhs.d = B.rows();
  rhs.x = const_cast<double*>(B.data());
  rhs.xtype = CHOLMOD_REAL;
  rhs.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* x = cholmod_l_solve(CHOLMOD_A, impl_->factor, &rhs, c);
  if (!x) throw std::runtime_error("CHOLMOD solve failed (out of memory?)");
  Eigen::MatrixXd out = Eigen::Map<Eigen::MatrixXd>(static_cast<double*>(x->x), B.rows(), B.cols());
  cholmod_l_free_dense(&x, c);
  return out;
}

Eigen::VectorXd SparseCholesky::solve(const Eigen::VectorXd& b) const {
  return solve(Eigen::MatrixXd(b)).col(0);
}

}  // namespace contact3d
