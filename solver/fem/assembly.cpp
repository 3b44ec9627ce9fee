#include "fem/assembly.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <thread>

#include "base/errors.hpp"

namespace contact3d {
namespace {

TetCoords coords(const Mesh& m, const std::array<int, 4>& t) {
  return {m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]};
}

std::string list_tags(const std::vector<std::size_t>& tags) {
  std::string s;
  for (std::size_t i = 0; i < tags.size() && i < 10; ++i) s += (i ? ", " : "") + std::to_string(tags[i]);
  if (tags.size() > 10) s += ", ... (" + std::to_string(tags.size()) + " in all)";
  return s;
}

}  // namespace

void check_tet_orientation(const Mesh& mesh) {
  if (mesh.tets.empty()) throw InputError("the mesh has no tetrahedra (4-node elements)");
  std::vector<std::size_t> inverted, degenerate;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const TetCoords x = coords(mesh, mesh.tets[e]);
    double h = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) h = std::max(h, (x[a] - x[b]).norm());
    const double v = tet_volume(x);
    if (!std::isfinite(v) || std::abs(v) <= 1e-10 * h * h * h) degenerate.push_back(mesh.tet_tags[e]);
    else if (v < 0) inverted.push_back(mesh.tet_tags[e]);
  }
  if (!degenerate.empty())
    throw InputError("degenerate (zero-volume) tetrahedra, element tags: " + list_tags(degenerate));
  if (!inverted.empty())
    throw InputError("inverted tetrahedra (negative volume), element tags: " + list_tags(inverted));
}

Eigen::SparseMatrix<double> assemble_stiffness_triplets(const Mesh& mesh, const DofMap& dofs,
                                                        const Material& material) {
  const Matrix6d D = hooke_matrix(material);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(mesh.tets.size() * 144);
  for (const auto& t : mesh.tets) {
    const Matrix12d Ke = element_stiffness(coords(mesh, t), D);
    std::array<int, 12> idx{};
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c) idx[3 * a + c] = dofs.dof(t[a], c);
    for (int i = 0; i < 12; ++i) {
      if (idx[i] < 0) continue;
      for (int j = 0; j < 12; ++j)
        if (idx[j] >= 0) entries.emplace_back(idx[i], idx[j], Ke(i, j));
    }
  }
  Eigen::SparseMatrix<double> K(dofs.n_free, dofs.n_free);
  K.setFromTriplets(entries.begin(), entries.end());
  return K;
}

namespace {

// True when every node has either no free dof or three consecutive ones, ascending with the
// node index (what make_dof_map produces): then K has a 3x3-block pattern known in advance.
bool has_node_block_layout(const DofMap& dofs) {
  int next = 0;
  for (int v = 0; v < dofs.n_nodes; ++v) {
    const int d0 = dofs.free_index[3 * v], d1 = dofs.free_index[3 * v + 1], d2 = dofs.free_index[3 * v + 2];
    if (d0 < 0 && d1 < 0 && d2 < 0) continue;
    if (d0 != next || d1 != next + 1 || d2 != next + 2) return false;
    next += 3;
  }
  return next == dofs.n_free;
}

// fn(lo, hi) over [0, count) split across the cores; an exception in a worker (e.g. bad_alloc)
// is rethrown here after all workers joined, not left to terminate the process.
template <class Fn>
void parallel_for(std::size_t count, Fn fn) {
  const unsigned threads = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
  if (threads == 1 || count < 2048) { fn(std::size_t(0), count); return; }
  std::vector<std::thread> pool;
  std::vector<std::exception_ptr> errors(threads);
  const std::size_t chunk = (count + threads - 1) / threads;
  for (unsigned t = 0; t < threads; ++t) {
    const std::size_t lo = t * chunk, hi = std::min(count, lo + chunk);
    if (lo < hi)
      pool.emplace_back([&, t, lo, hi] {
        try { fn(lo, hi); } catch (...) { errors[t] = std::current_exception(); }
      });
  }
  for (auto& th : pool) th.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

// Tets around every node, CSR: tets_of(v) = tet[first[v] .. first[v+1]).
struct NodeTets {
  std::vector<int> first, tet;
  NodeTets(const Mesh& mesh) : first(mesh.nodes.size() + 1, 0) {
    for (const auto& t : mesh.tets)
      for (int v : t) ++first[v + 1];
    for (std::size_t v = 0; v < mesh.nodes.size(); ++v) first[v + 1] += first[v];
    tet.resize(first.back());
    std::vector<int> next(first.begin(), first.end() - 1);
    for (std::size_t e = 0; e < mesh.tets.size(); ++e)
      for (int v : mesh.tets[e]) tet[next[v]++] = static_cast<int>(e);
  }
};

// The 3x3 block of |T| Bᵀ D B coupling node a (rows) to node b (columns) of a tet, for the
// isotropic D of hooke_matrix, from the hat gradients g_a, g_b:
//   |T| (λ g_a g_bᵀ + μ g_b g_aᵀ + μ (g_a·g_b) I)   (λ, μ the Lamé constants).
// Equal to the block of element_stiffness (tested against the triplet assembly).
Eigen::Matrix3d isotropic_block(const Eigen::Vector3d& ga, const Eigen::Vector3d& gb, double lame_lambda, double mu, double volume) {
  Eigen::Matrix3d block = lame_lambda * ga * gb.transpose() + mu * gb * ga.transpose();
  block.diagonal().array() += mu * ga.dot(gb);
  return volume * block;
}

}  // namespace

// Column-block assembly: every free node owns the 3 columns of its dofs and fills them from its
// own tets (the block |T| B_aᵀ D B_b for each node a of a tet around it), so nodes are independent —
// parallel without colouring — and every write goes to the node's own contiguous columns.
Eigen::SparseMatrix<double> assemble_stiffness(const Mesh& mesh, const DofMap& dofs,
                                               const Material& material) {
  if (!has_node_block_layout(dofs)) return assemble_stiffness_triplets(mesh, dofs, material);
  const int n_nodes = dofs.n_nodes;
  const NodeTets around(mesh);
  // Hat gradients and volume of every tet, once.
  std::vector<std::array<Eigen::Vector3d, 4>> grad(mesh.tets.size());
  std::vector<double> volume(mesh.tets.size());
  parallel_for(mesh.tets.size(), [&](std::size_t lo, std::size_t hi) {
    for (std::size_t e = lo; e < hi; ++e) {
      const TetCoords x = coords(mesh, mesh.tets[e]);
      const Matrix6x12d B = strain_matrix(x);
      for (int a = 0; a < 4; ++a) grad[e][a] = Eigen::Vector3d(B(0, 3 * a), B(1, 3 * a + 1), B(2, 3 * a + 2));
      volume[e] = std::abs(tet_volume(x));
    }
  });
  // Free neighbours of every free node (itself included), sorted: the block pattern of K.
  std::vector<std::vector<int>> nbr(n_nodes);
  parallel_for(n_nodes, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t v = lo; v < hi; ++v) {
      if (dofs.dof(static_cast<int>(v), 0) < 0) continue;
      auto& list = nbr[v];
      for (int k = around.first[v]; k < around.first[v + 1]; ++k)
        for (int a : mesh.tets[around.tet[k]])
          if (dofs.dof(a, 0) >= 0) list.push_back(a);
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
    }
  });
  std::vector<Eigen::Index> col_ptr(dofs.n_free + 1, 0);
  for (int v = 0; v < n_nodes; ++v)
    if (const int d = dofs.dof(v, 0); d >= 0)
      for (int c = 0; c < 3; ++c) col_ptr[d + c + 1] = static_cast<Eigen::Index>(3 * nbr[v].size());
  for (int j = 0; j < dofs.n_free; ++j) col_ptr[j + 1] += col_ptr[j];
  if (col_ptr.back() > std::numeric_limits<int>::max())
    throw InputError("the stiffness matrix would have " + std::to_string(col_ptr.back()) +
                     " nonzeros, beyond the 32-bit indices of its sparse storage: use a coarser mesh");
  // Filled in place (no copy of the arrays): K's compressed storage is exactly this layout.
  Eigen::SparseMatrix<double> K(dofs.n_free, dofs.n_free);
  K.resizeNonZeros(static_cast<Eigen::Index>(col_ptr.back()));
  std::copy(col_ptr.begin(), col_ptr.end(), K.outerIndexPtr());
  int* row_idx = K.innerIndexPtr();
  double* values = K.valuePtr();
  const double E = material.young, nu = material.poisson;
  const double lame_lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));  // as in hooke_matrix
  parallel_for(n_nodes, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t v = lo; v < hi; ++v) {
      const int d = dofs.dof(static_cast<int>(v), 0);
      if (d < 0) continue;
      const auto& list = nbr[v];
      for (int c = 0; c < 3; ++c) {
        Eigen::Index k = col_ptr[d + c];
        for (int a : list)
          for (int r = 0; r < 3; ++r) { row_idx[k] = dofs.dof(a, r); values[k++] = 0.0; }
      }
      for (int k = around.first[v]; k < around.first[v + 1]; ++k) {
        const int e = around.tet[k];
        const auto& t = mesh.tets[e];
        const int b = static_cast<int>(std::find(t.begin(), t.end(), static_cast<int>(v)) - t.begin());
        for (int a = 0; a < 4; ++a) {
          if (dofs.dof(t[a], 0) < 0) continue;
          const Eigen::Matrix3d block = isotropic_block(grad[e][a], grad[e][b], lame_lambda, mu, volume[e]);
          const auto offset = 3 * (std::lower_bound(list.begin(), list.end(), t[a]) - list.begin());
          for (int cb = 0; cb < 3; ++cb) {
            double* column = values + col_ptr[d + cb] + offset;
            for (int ca = 0; ca < 3; ++ca) column[ca] += block(ca, cb);
          }
        }
      }
    }
  });
  return K;
}

Eigen::VectorXd assemble_load(const Mesh& mesh, const DofMap& dofs,
                              const std::vector<Traction>& tractions,
                              const Eigen::Vector3d& body_force) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dofs.n_free);
  auto add = [&](int node, const Eigen::Vector3d& load) {
    for (int c = 0; c < 3; ++c)
      if (int d = dofs.dof(node, c); d >= 0) f[d] += load[c];
  };
  for (const auto& tr : tractions)
    for (int t : mesh.triangles_of_group(tr.group)) {
      const auto& tri = mesh.triangles[t];
      const double area =
          0.5 * (mesh.nodes[tri[1]] - mesh.nodes[tri[0]]).cross(mesh.nodes[tri[2]] - mesh.nodes[tri[0]]).norm();
      for (int v : tri) add(v, tr.value * (area / 3.0));
    }
  if (body_force.squaredNorm() > 0)
    for (const auto& t : mesh.tets) {
      const double vol = std::abs(tet_volume(coords(mesh, t)));
      for (int v : t) add(v, body_force * (vol / 4.0));
    }
  // Loads so large that |f|² overflows would turn every norm in the dual QP into inf/NaN.
  if (!std::isfinite(f.squaredNorm()))
    throw InputError("the load vector overflows double precision (|f|² is not finite): tractions or body force too "
                     "large; rescale the units");
  return f;
}

Eigen::VectorXd expand_to_nodes(const DofMap& dofs, const Eigen::VectorXd& u_free) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * dofs.n_nodes);
  for (int i = 0; i < 3 * dofs.n_nodes; ++i)
    if (dofs.free_index[i] >= 0) u[i] = u_free[dofs.free_index[i]];
  return u;
}

}  // namespace contact3d
