#include "linalg/sparse_forward_solve.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "linalg/blas.hpp"

namespace contact3d {
namespace {

// The elimination tree of the supernodes: owner of every pivot position, parent of every supernode
// (the owner of its first row below the diagonal block; -1 for a root).
struct SupernodeTree {
  std::vector<std::int64_t> position;  // row of K -> pivot position
  std::vector<std::int64_t> owner;     // pivot position -> supernode
  std::vector<std::int64_t> parent;

  explicit SupernodeTree(const SparseCholesky::Supernodes& L) : position(L.n), owner(L.n), parent(L.count, -1) {
    for (std::int64_t k = 0; k < L.n; ++k) position[L.perm[k]] = k;
    for (std::int64_t s = 0; s < L.count; ++s)
      for (std::int64_t j = L.super[s]; j < L.super[s + 1]; ++j) owner[j] = s;
    for (std::int64_t s = 0; s < L.count; ++s) {
      const std::int64_t ncols = L.super[s + 1] - L.super[s], nrows = L.pi[s + 1] - L.pi[s];
      if (nrows > ncols) parent[s] = owner[L.rows[L.pi[s] + ncols]];
    }
  }
};

// One block of columns: the supernodes of their reach, each given a range of rows in a compact
// R × columns workspace.
class ReachBlock {
 public:
  explicit ReachBlock(std::int64_t supernodes) : offset_(supernodes, -1) {}

  // Adds the supernodes from `s` up to the root that are not in the block yet.
  void add_path(const SparseCholesky::Supernodes& L, const SupernodeTree& tree, std::int64_t s) {
    for (; s >= 0 && offset_[s] < 0; s = tree.parent[s]) {
      offset_[s] = rows_;
      rows_ += L.super[s + 1] - L.super[s];
      supernodes_.push_back(s);
    }
  }
  std::int64_t rows() const { return rows_; }
  std::int64_t offset(std::int64_t s) const { return offset_[s]; }
  // Children before parents: supernodes are numbered so that a parent comes after its children.
  const std::vector<std::int64_t>& ascending() {
    std::sort(supernodes_.begin(), supernodes_.end());
    return supernodes_;
  }
  void clear() {
    for (std::int64_t s : supernodes_) offset_[s] = -1;
    supernodes_.clear();
    rows_ = 0;
  }

 private:
  std::vector<std::int64_t> offset_;  // first workspace row of a supernode in the block, or -1
  std::vector<std::int64_t> supernodes_;
  std::int64_t rows_ = 0;
};

// X ← L⁻¹ X over the block's supernodes, X the R × cols workspace (column-major, leading dimension R).
void substitute(const SparseCholesky::Supernodes& L, const SupernodeTree& tree, const ReachBlock& block,
                const std::vector<std::int64_t>& reach, int cols, std::vector<double>& X, std::vector<double>& below) {
  const int R = static_cast<int>(block.rows());
  const double one = 1, zero = 0;
  for (std::int64_t s : reach) {
    const int nc = static_cast<int>(L.super[s + 1] - L.super[s]);
    const int nrows = static_cast<int>(L.pi[s + 1] - L.pi[s]), nb = nrows - nc;
    const double* values = L.values + L.px[s];
    double* Xs = X.data() + block.offset(s);
    dtrsm_("L", "L", "N", "N", &nc, &cols, &one, values, &nrows, Xs, &R);
    if (nb == 0) continue;
    below.resize(static_cast<std::size_t>(nb) * cols);
    dgemm_("N", "N", &nb, &cols, &nc, &one, values + nc, &nrows, Xs, &R, &zero, below.data(), &nb);
    const std::int64_t* rows = L.rows + L.pi[s] + nc;
    for (int p = 0; p < nb; ++p) {
      const std::int64_t t = tree.owner[rows[p]];
      const std::int64_t local = block.offset(t) + rows[p] - L.super[t];
      for (int c = 0; c < cols; ++c)
        X[local + static_cast<std::int64_t>(c) * R] -= below[p + static_cast<std::size_t>(c) * nb];
    }
  }
}

}  // namespace

void forward_solve_sparse_columns(
    const SparseCholesky& factor, const Eigen::SparseMatrix<double>& rhs, int max_block_columns,
    std::int64_t block_bytes,
    const std::function<void(int column, std::span<const std::int64_t> rows, std::span<const double> values)>& visit) {
  if (factor.augmented()) throw std::logic_error("forward_solve_sparse_columns: not for the augmented factor");
  if (rhs.rows() != factor.size()) throw std::invalid_argument("forward_solve_sparse_columns: sizes differ");
  const SparseCholesky::Supernodes L = factor.supernodes();
  const SupernodeTree tree(L);
  const int m = static_cast<int>(rhs.cols());

  // Each column enters the tree at its lowest supernode; sorted by it, neighbours share their paths.
  std::vector<std::int64_t> entry(m, L.count);
  for (int j = 0; j < m; ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(rhs, j); it; ++it)
      entry[j] = std::min(entry[j], tree.owner[tree.position[it.row()]]);
  std::vector<int> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return entry[a] < entry[b]; });

  ReachBlock block(L.count);
  std::vector<double> X, below, values;
  std::vector<std::int64_t> rows;
  for (int start = 0; start < m;) {
    int cols = 0;
    while (start + cols < m && cols < std::max(1, max_block_columns)) {
      const int j = order[start + cols];
      for (Eigen::SparseMatrix<double>::InnerIterator it(rhs, j); it; ++it)
        block.add_path(L, tree, tree.owner[tree.position[it.row()]]);
      ++cols;
      if (block.rows() * cols * static_cast<std::int64_t>(sizeof(double)) >= block_bytes) break;
    }
    const std::int64_t R = block.rows();
    X.assign(static_cast<std::size_t>(R * cols), 0.0);
    for (int c = 0; c < cols; ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(rhs, order[start + c]); it; ++it) {
        const std::int64_t p = tree.position[it.row()], s = tree.owner[p];
        X[block.offset(s) + p - L.super[s] + c * R] += it.value();
      }
    const std::vector<std::int64_t>& reach = block.ascending();
    if (R > 0) substitute(L, tree, block, reach, cols, X, below);
    for (int c = 0; c < cols; ++c) {
      rows.clear();
      values.clear();
      for (std::int64_t s : reach)
        for (std::int64_t k = 0; k < L.super[s + 1] - L.super[s]; ++k) {
          const double v = X[block.offset(s) + k + c * R];
          if (v != 0) {
            rows.push_back(L.super[s] + k);
            values.push_back(v);
          }
        }
      visit(order[start + c], rows, values);
    }
    block.clear();
    start += cols;
  }
}

}  // namespace contact3d
