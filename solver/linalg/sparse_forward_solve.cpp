#include "linalg/sparse_forward_solve.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "linalg/blas.hpp"

namespace contact3d {
namespace {

// The elimination tree of the supernodes with leading columns — K's, not the multipliers' that an
// augmented factor orders last (pivot positions from `lead` on): owner of every leading pivot position,
// parent of every supernode (the owner of its first leading row below the diagonal block; -1 for a
// root of K's factor), and of each supernode its leading columns and leading rows below them.
struct SupernodeTree {
  std::vector<std::int64_t> position;  // row of the factored matrix -> pivot position
  std::vector<std::int64_t> owner;     // leading pivot position -> supernode
  std::vector<std::int64_t> parent;
  std::vector<int> columns, below;  // per supernode: leading columns, leading rows below them

  SupernodeTree(const SparseCholesky::Supernodes& L, std::int64_t lead)
      : position(L.n), owner(lead), parent(L.count, -1), columns(L.count, 0), below(L.count, 0) {
    for (std::int64_t k = 0; k < L.n; ++k) position[L.perm[k]] = k;
    for (std::int64_t s = 0; s < L.count && L.super[s] < lead; ++s) {
      columns[s] = static_cast<int>(std::min(L.super[s + 1], lead) - L.super[s]);
      for (std::int64_t j = L.super[s]; j < L.super[s] + columns[s]; ++j) owner[j] = s;
    }
    for (std::int64_t s = 0; s < L.count && L.super[s] < lead; ++s) {
      const std::int64_t ncols = L.super[s + 1] - L.super[s], nrows = L.pi[s + 1] - L.pi[s];
      // Rows below the diagonal block ascend, the multipliers' (trailing) last.
      const std::int64_t* rows = L.rows + L.pi[s] + ncols;
      below[s] = static_cast<int>(std::lower_bound(rows, rows + (nrows - ncols), lead) - rows);
      if (below[s] > 0) parent[s] = owner[rows[0]];
    }
  }
};

// One block of columns: the supernodes of their reach, each given a range of rows in a compact
// R × columns workspace.
class ReachBlock {
 public:
  explicit ReachBlock(std::int64_t supernodes) : offset_(supernodes, -1) {}

  // Adds the supernodes from `s` up to the root that are not in the block yet.
  void add_path(const SupernodeTree& tree, std::int64_t s) {
    for (; s >= 0 && offset_[s] < 0; s = tree.parent[s]) {
      offset_[s] = rows_;
      rows_ += tree.columns[s];
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
    const int nc = tree.columns[s], nb = tree.below[s];  // K's part of the supernode
    const int all_columns = static_cast<int>(L.super[s + 1] - L.super[s]);
    const int nrows = static_cast<int>(L.pi[s + 1] - L.pi[s]);
    const double* values = L.values + L.px[s];
    double* Xs = X.data() + block.offset(s);
    dtrsm_("L", "L", "N", "N", &nc, &cols, &one, values, &nrows, Xs, &R);
    if (nb == 0) continue;
    below.resize(static_cast<std::size_t>(nb) * cols);
    dgemm_("N", "N", &nb, &cols, &nc, &one, values + all_columns, &nrows, Xs, &R, &zero, below.data(), &nb);
    const std::int64_t* rows = L.rows + L.pi[s] + all_columns;
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
  if (rhs.rows() != factor.size()) throw std::invalid_argument("forward_solve_sparse_columns: sizes differ");
  const SparseCholesky::Supernodes L = factor.supernodes();
  const SupernodeTree tree(L, factor.size());
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
        block.add_path(tree, tree.owner[tree.position[it.row()]]);
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
        for (std::int64_t k = 0; k < tree.columns[s]; ++k) {
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

namespace {

// Where each of `sub` (ascending, a subset of `set`) lies in `set` (ascending).
void positions_in(const std::vector<int>& sub, const std::vector<int>& set, std::vector<int>& out) {
  out.resize(sub.size());
  auto from = set.begin();
  for (std::size_t k = 0; k < sub.size(); ++k) {
    from = std::lower_bound(from, set.end(), sub[k]);
    out[k] = static_cast<int>(from - set.begin());
  }
}

// The columns of `rhs` reaching each supernode of K's rows: its own entries' and its children's
// (children come first, and hand theirs up before the parent sorts its list).
std::vector<std::vector<int>> reaching_columns(const SparseCholesky::Supernodes& L, const SupernodeTree& tree,
                                               std::int64_t rows, const Eigen::SparseMatrix<double>& rhs) {
  std::vector<std::vector<int>> reaching(static_cast<std::size_t>(L.count));
  for (int j = 0; j < rhs.cols(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(rhs, j); it; ++it)
      reaching[static_cast<std::size_t>(tree.owner[tree.position[it.row()]])].push_back(j);
  for (std::int64_t s = 0; s < L.count && L.super[s] < rows; ++s) {
    std::vector<int>& mine = reaching[static_cast<std::size_t>(s)];
    std::sort(mine.begin(), mine.end());
    mine.erase(std::unique(mine.begin(), mine.end()), mine.end());
    if (const std::int64_t p = tree.parent[s]; p >= 0)
      reaching[static_cast<std::size_t>(p)].insert(reaching[static_cast<std::size_t>(p)].end(), mine.begin(),
                                                   mine.end());
  }
  return reaching;
}

}  // namespace

std::int64_t forward_solved_block_entries(const SparseCholesky& factor, const Eigen::SparseMatrix<double>& rhs) {
  if (rhs.rows() != factor.size()) throw std::invalid_argument("forward_solved_block_entries: sizes differ");
  const SparseCholesky::Supernodes L = factor.supernodes();
  const SupernodeTree tree(L, factor.size());
  const std::vector<std::vector<int>> reaching = reaching_columns(L, tree, factor.size(), rhs);
  std::int64_t entries = 0;
  for (std::int64_t s = 0; s < L.count && L.super[s] < factor.size(); ++s)
    entries += static_cast<std::int64_t>(tree.columns[s]) * static_cast<std::int64_t>(reaching[s].size());
  return entries;
}

ForwardSolvedBlocks forward_solve_by_supernodes(const SparseCholesky& factor, const Eigen::SparseMatrix<double>& rhs) {
  if (rhs.rows() != factor.size()) throw std::invalid_argument("forward_solve_by_supernodes: sizes differ");
  const SparseCholesky::Supernodes L = factor.supernodes();
  const SupernodeTree tree(L, factor.size());
  ForwardSolvedBlocks out;
  out.rows = factor.size();
  out.columns = static_cast<int>(rhs.cols());
  out.first_row.assign(L.super, L.super + L.count);
  out.reaching = reaching_columns(L, tree, out.rows, rhs);
  out.block.assign(static_cast<std::size_t>(L.count), {});
  for (std::int64_t s = 0; s < L.count && L.super[s] < out.rows; ++s)
    out.block[static_cast<std::size_t>(s)].assign(
        static_cast<std::size_t>(tree.columns[s]) * out.reaching[static_cast<std::size_t>(s)].size(), 0.0);
  for (int j = 0; j < out.columns; ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(rhs, j); it; ++it) {
      const std::int64_t p = tree.position[it.row()], s = tree.owner[p];
      const std::vector<int>& cols = out.reaching[static_cast<std::size_t>(s)];
      const auto c = std::lower_bound(cols.begin(), cols.end(), j) - cols.begin();
      out.block[static_cast<std::size_t>(s)]
               [static_cast<std::size_t>(p - L.super[s]) + static_cast<std::size_t>(c) * tree.columns[s]] += it.value();
    }

  // Bottom up: solve the supernode's block, then subtract its update from its ancestors' blocks.
  std::vector<double> update;
  std::vector<int> where;
  const double one = 1, zero = 0;
  for (std::int64_t s = 0; s < L.count && L.super[s] < out.rows; ++s) {
    const std::vector<int>& cols = out.reaching[static_cast<std::size_t>(s)];
    if (cols.empty()) continue;
    const int nc = tree.columns[s], nb = tree.below[s], c = static_cast<int>(cols.size());
    const int all_columns = static_cast<int>(L.super[s + 1] - L.super[s]);
    const int nrows = static_cast<int>(L.pi[s + 1] - L.pi[s]);
    const double* values = L.values + L.px[s];
    double* X = out.block[static_cast<std::size_t>(s)].data();
    dtrsm_("L", "L", "N", "N", &nc, &c, &one, values, &nrows, X, &nc);
    if (nb == 0) continue;
    update.resize(static_cast<std::size_t>(nb) * c);
    dgemm_("N", "N", &nb, &c, &nc, &one, values + all_columns, &nrows, X, &nc, &zero, update.data(), &nb);
    const std::int64_t* rows = L.rows + L.pi[s] + all_columns;
    for (int first = 0; first < nb;) {  // the rows below, ascending: grouped by the ancestor that holds them
      const std::int64_t t = tree.owner[rows[first]];
      int last = first;
      while (last < nb && tree.owner[rows[last]] == t) ++last;
      const std::vector<int>& above = out.reaching[static_cast<std::size_t>(t)];
      positions_in(cols, above, where);
      double* Y = out.block[static_cast<std::size_t>(t)].data();
      const std::size_t ld = static_cast<std::size_t>(tree.columns[t]);
      for (int k = 0; k < c; ++k) {
        double* to = Y + static_cast<std::size_t>(where[static_cast<std::size_t>(k)]) * ld;
        const double* from = update.data() + static_cast<std::size_t>(k) * nb;
        for (int r = first; r < last; ++r) to[rows[r] - L.super[t]] -= from[r];
      }
      first = last;
    }
  }
  return out;
}

Eigen::MatrixXd ForwardSolvedBlocks::gram() const {
  const int m = columns;
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(m, m);
  std::vector<double> G;
  const double one = 1, zero = 0;
  for (std::size_t s = 0; s < reaching.size(); ++s) {
    const std::vector<int>& cols = reaching[s];
    if (cols.empty()) continue;
    const int c = static_cast<int>(cols.size()), k = static_cast<int>(block[s].size() / cols.size());
    if (c == m) {  // every column reaches s (the top of the tree): straight into Q
      dsyrk_("L", "T", &c, &k, &one, block[s].data(), &k, &one, Q.data(), &m);
      continue;
    }
    G.resize(static_cast<std::size_t>(c) * c);
    dsyrk_("L", "T", &c, &k, &one, block[s].data(), &k, &zero, G.data(), &c);
    for (int j = 0; j < c; ++j) {
      double* to = Q.data() + static_cast<std::size_t>(cols[static_cast<std::size_t>(j)]) * m;
      const double* from = G.data() + static_cast<std::size_t>(j) * c;
      for (int i = j; i < c; ++i) to[cols[static_cast<std::size_t>(i)]] += from[i];
    }
  }
  return Q.selfadjointView<Eigen::Lower>();
}

Eigen::VectorXd ForwardSolvedBlocks::column_squared_norms() const {
  Eigen::VectorXd norms = Eigen::VectorXd::Zero(columns);
  for (std::size_t s = 0; s < reaching.size(); ++s) {
    const std::vector<int>& cols = reaching[s];
    if (cols.empty()) continue;
    const Eigen::Index k = static_cast<Eigen::Index>(block[s].size() / cols.size());
    const Eigen::Map<const Eigen::MatrixXd> X(block[s].data(), k, static_cast<Eigen::Index>(cols.size()));
    for (std::size_t j = 0; j < cols.size(); ++j) norms[cols[j]] += X.col(static_cast<Eigen::Index>(j)).squaredNorm();
  }
  return norms;
}

Eigen::MatrixXd ForwardSolvedBlocks::gram_product(const Eigen::MatrixXd& V) const {
  if (V.rows() != columns) throw std::invalid_argument("ForwardSolvedBlocks::gram_product: sizes differ");
  const int n = static_cast<int>(V.cols()), inc = 1;
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(columns, n);
  std::vector<double> gathered, rows_times_v;
  const double one = 1, zero = 0;
  for (std::size_t s = 0; s < reaching.size(); ++s) {
    const std::vector<int>& cols = reaching[s];
    if (cols.empty() || n == 0) continue;
    const int c = static_cast<int>(cols.size()), k = static_cast<int>(block[s].size() / cols.size());
    gathered.resize(static_cast<std::size_t>(c) * n);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < c; ++i)
        gathered[static_cast<std::size_t>(i + j * c)] = V(cols[static_cast<std::size_t>(i)], j);
    rows_times_v.resize(static_cast<std::size_t>(k) * n);
    const double* X = block[s].data();
    if (n == 1) {
      dgemv_("N", &k, &c, &one, X, &k, gathered.data(), &inc, &zero, rows_times_v.data(), &inc);
      dgemv_("T", &k, &c, &one, X, &k, rows_times_v.data(), &inc, &zero, gathered.data(), &inc);
    } else {
      dgemm_("N", "N", &k, &n, &c, &one, X, &k, gathered.data(), &c, &zero, rows_times_v.data(), &k);
      dgemm_("T", "N", &c, &n, &k, &one, X, &k, rows_times_v.data(), &k, &zero, gathered.data(), &c);
    }
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < c; ++i)
        out(cols[static_cast<std::size_t>(i)], j) += gathered[static_cast<std::size_t>(i + j * c)];
  }
  return out;
}

std::int64_t ForwardSolvedBlocks::entries() const {
  std::int64_t total = 0;
  for (const auto& b : block) total += static_cast<std::int64_t>(b.size());
  return total;
}

void ForwardSolvedBlocks::subtract_product(const Eigen::VectorXd& lambda, Eigen::VectorXd& x) const {
  if (lambda.size() != columns || x.size() < rows)
    throw std::invalid_argument("ForwardSolvedBlocks::subtract_product: sizes differ");
  std::vector<double> gathered;
  const int one = 1;
  const double minus_one = -1, plus_one = 1;
  for (std::size_t s = 0; s < reaching.size(); ++s) {
    const std::vector<int>& cols = reaching[s];
    if (cols.empty()) continue;
    const int c = static_cast<int>(cols.size()), k = static_cast<int>(block[s].size() / cols.size());
    gathered.resize(cols.size());
    for (std::size_t j = 0; j < cols.size(); ++j) gathered[j] = lambda[cols[j]];
    dgemv_("N", &k, &c, &minus_one, block[s].data(), &k, gathered.data(), &one, &plus_one, x.data() + first_row[s],
           &one);
  }
}

}  // namespace contact3d
