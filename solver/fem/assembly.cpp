#include "fem/assembly.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <stdexcept>
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
  if (mesh.tets.empty())
    throw InputError(
        "the mesh has no tetrahedra (4-node elements): mesh the volume in 3D (gmsh -3), and put it in a "
        "physical group (a .geo with physical groups saves only their elements: add a Physical Volume)");
  std::vector<std::size_t> inverted, degenerate;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const TetCoords x = coords(mesh, mesh.tets[e]);
    double h = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) h = std::max(h, (x[a] - x[b]).norm());
    const double v = tet_volume(x);
    if (!std::isfinite(v) || std::abs(v) <= 1e-10 * h * h * h)
      degenerate.push_back(mesh.tet_tags[e]);
    else if (v < 0)
      inverted.push_back(mesh.tet_tags[e]);
  }
  if (!degenerate.empty())
    throw InputError("degenerate (zero-volume) tetrahedra, element tags: " + list_tags(degenerate));
  if (!inverted.empty())
    throw InputError("inverted tetrahedra (negative volume), element tags: " + list_tags(inverted));
}

Eigen::SparseMatrix<double> assemble_stiffness_triplets(const Mesh& mesh, const DofMap& dofs,
                                                        const TetMaterials& material) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(mesh.tets.size() * 144);
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const auto& t = mesh.tets[e];
    const Matrix12d Ke = element_stiffness(coords(mesh, t), hooke_matrix(material[e]));
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

Eigen::VectorXd apply_stiffness(const Mesh& mesh, const DofMap& dofs, const TetMaterials& material,
                                const Eigen::VectorXd& w) {
  // K_ff·w is the free rows of the whole-mesh product with zeros at the prescribed components.
  Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * dofs.n_nodes);
  for (int i = 0; i < 3 * dofs.n_nodes; ++i)
    if (dofs.free_index[i] >= 0) u[i] = w[dofs.free_index[i]];
  const Eigen::VectorXd Ku = internal_minus_external(mesh, material, {}, Eigen::Vector3d::Zero(), u);
  Eigen::VectorXd Kw(dofs.n_free);
  for (int i = 0; i < 3 * dofs.n_nodes; ++i)
    if (dofs.free_index[i] >= 0) Kw[dofs.free_index[i]] = Ku[i];
  return Kw;
}

std::vector<double> stiffness_diagonal_at(const Mesh& mesh, const DofMap& dofs, const TetMaterials& material,
                                          const std::vector<int>& free_dofs) {
  std::vector<double> diagonal(free_dofs.size(), 0.0);
  std::vector<int> global(free_dofs.size(), -1);  // node · 3 + component of each
  for (int i = 0; i < 3 * dofs.n_nodes; ++i)
    for (std::size_t k = 0; k < free_dofs.size(); ++k)
      if (dofs.free_index[i] >= 0 && dofs.free_index[i] == free_dofs[k]) global[k] = i;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e)
    for (int a = 0; a < 4; ++a)
      for (std::size_t k = 0; k < free_dofs.size(); ++k) {
        if (global[k] < 0 || mesh.tets[e][a] != global[k] / 3) continue;
        const Matrix12d Ke = element_stiffness(coords(mesh, mesh.tets[e]), hooke_matrix(material[e]));
        diagonal[k] += Ke(3 * a + global[k] % 3, 3 * a + global[k] % 3);
      }
  return diagonal;
}

namespace {

// True when free dofs are numbered node by node, ascending, each node's free components in
// x, y, z order (what make_dof_map produces): then K's pattern follows from the node graph.
bool has_node_ordered_layout(const DofMap& dofs) {
  int next = 0;
  for (int i = 0; i < 3 * dofs.n_nodes; ++i)
    if (dofs.free_index[i] >= 0 && dofs.free_index[i] != next++) return false;
  return next == dofs.n_free;
}

int free_components(const DofMap& dofs, int node) {
  return (dofs.dof(node, 0) >= 0) + (dofs.dof(node, 1) >= 0) + (dofs.dof(node, 2) >= 0);
}

// fn(lo, hi) over [0, count) split across the cores; an exception in a worker (e.g. bad_alloc)
// is rethrown here after all workers joined, not left to terminate the process.
template <class Fn>
void parallel_for(std::size_t count, Fn fn) {
  const unsigned threads = std::max(1u, std::min(8u, std::thread::hardware_concurrency()));
  if (threads == 1 || count < 2048) {
    fn(std::size_t(0), count);
    return;
  }
  std::vector<std::thread> pool;
  std::vector<std::exception_ptr> errors(threads);
  const std::size_t chunk = (count + threads - 1) / threads;
  for (unsigned t = 0; t < threads; ++t) {
    const std::size_t lo = t * chunk, hi = std::min(count, lo + chunk);
    if (lo < hi)
      pool.emplace_back([&, t, lo, hi] {
        try {
          fn(lo, hi);
        } catch (...) { errors[t] = std::current_exception(); }
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
Eigen::Matrix3d isotropic_block(const Eigen::Vector3d& ga, const Eigen::Vector3d& gb, double lame_lambda, double mu,
                                double volume) {
  Eigen::Matrix3d block = lame_lambda * ga * gb.transpose() + mu * gb * ga.transpose();
  block.diagonal().array() += mu * ga.dot(gb);
  return volume * block;
}

}  // namespace

// Column-block assembly: every free node owns the 3 columns of its dofs and fills them from its
// own tets (the block |T| B_aᵀ D B_b for each node a of a tet around it), so nodes are independent —
// parallel without colouring — and every write goes to the node's own contiguous columns.
Eigen::SparseMatrix<double> assemble_stiffness(const Mesh& mesh, const DofMap& dofs, const TetMaterials& material) {
  if (!has_node_ordered_layout(dofs)) return assemble_stiffness_triplets(mesh, dofs, material);
  return assemble_stiffness_columns(mesh, dofs, material, 0, dofs.n_nodes);
}

int first_free_dof(const DofMap& dofs, int node) {
  for (int i = 3 * node; i < 3 * dofs.n_nodes; ++i)
    if (dofs.free_index[i] >= 0) return dofs.free_index[i];
  return dofs.n_free;
}

namespace {

// True when the free dofs increase node by node, component by component (gaps allowed: `mesh` may
// be a part of a larger mesh, numbered with that mesh's dofs).
bool dofs_increase_node_by_node(const DofMap& dofs) {
  int last = -1;
  for (int i = 0; i < 3 * dofs.n_nodes; ++i)
    if (const int d = dofs.free_index[i]; d >= 0) {
      if (d <= last) return false;
      last = d;
    }
  return true;
}

}  // namespace

Eigen::SparseMatrix<double> assemble_stiffness_columns(const Mesh& mesh, const DofMap& dofs,
                                                       const TetMaterials& material, int first_node, int last_node) {
  const int first_dof = first_free_dof(dofs, first_node);
  int n_cols = 0, last_dof = first_dof - 1;
  for (int i = 3 * first_node; i < 3 * last_node; ++i)
    if (dofs.free_index[i] >= 0) {
      ++n_cols;
      last_dof = dofs.free_index[i];
    }
  if (!dofs_increase_node_by_node(dofs) || last_dof - first_dof + 1 != n_cols)
    throw std::logic_error("assemble_stiffness_columns: the free dofs are not numbered node by node");
  const NodeTets around(mesh);
  // The tets around the nodes, each once, and the slot of each in the per-tet arrays.
  std::vector<int> slot(mesh.tets.size(), -1), used;
  for (int v = first_node; v < last_node; ++v)
    for (int k = around.first[v]; k < around.first[v + 1]; ++k)
      if (const int e = around.tet[k]; slot[e] < 0) {
        slot[e] = static_cast<int>(used.size());
        used.push_back(e);
      }
  // Hat gradients, volume and Lamé constants of every such tet, once.
  std::vector<std::array<Eigen::Vector3d, 4>> grad(used.size());
  std::vector<double> volume(used.size());
  std::vector<Eigen::Vector2d> lame(used.size());  // (λ, μ) as in hooke_matrix
  parallel_for(used.size(), [&](std::size_t lo, std::size_t hi) {
    for (std::size_t s = lo; s < hi; ++s) {
      const int e = used[s];
      const TetCoords x = coords(mesh, mesh.tets[e]);
      const Matrix6x12d B = strain_matrix(x);
      for (int a = 0; a < 4; ++a) grad[s][a] = Eigen::Vector3d(B(0, 3 * a), B(1, 3 * a + 1), B(2, 3 * a + 2));
      volume[s] = std::abs(tet_volume(x));
      const double E = material[e].young, nu = material[e].poisson;
      lame[s] = Eigen::Vector2d(E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu)));
    }
  });
  // Neighbours of every node of the range with a free dof (itself included) that have free dofs,
  // sorted, and the offset of each neighbour's rows within a column: the pattern of the columns.
  std::vector<int> n_free_of(dofs.n_nodes);
  for (int v = 0; v < dofs.n_nodes; ++v) n_free_of[v] = free_components(dofs, v);
  const auto n_range = static_cast<std::size_t>(last_node - first_node);
  std::vector<std::vector<int>> nbr(n_range), row_offset(n_range);
  parallel_for(n_range, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t i = lo; i < hi; ++i) {
      const int v = first_node + static_cast<int>(i);
      if (n_free_of[v] == 0) continue;
      auto& list = nbr[i];
      for (int k = around.first[v]; k < around.first[v + 1]; ++k)
        for (int a : mesh.tets[around.tet[k]])
          if (n_free_of[a] > 0) list.push_back(a);
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
      auto& offset = row_offset[i];
      offset.resize(list.size() + 1, 0);
      for (std::size_t j = 0; j < list.size(); ++j) offset[j + 1] = offset[j] + n_free_of[list[j]];
    }
  });
  std::vector<Eigen::Index> col_ptr(static_cast<std::size_t>(n_cols) + 1, 0);
  for (int v = first_node; v < last_node; ++v)
    for (int c = 0; c < 3; ++c)
      if (const int d = dofs.dof(v, c); d >= 0)
        col_ptr[d - first_dof + 1] = static_cast<Eigen::Index>(row_offset[v - first_node].back());
  for (int j = 0; j < n_cols; ++j) col_ptr[j + 1] += col_ptr[j];
  if (col_ptr.back() > std::numeric_limits<int>::max())
    throw InputError("the stiffness matrix would have " + std::to_string(col_ptr.back()) +
                     " nonzeros, beyond the 32-bit indices of its sparse storage: use a coarser mesh");
  // Filled in place (no copy of the arrays): K's compressed storage is exactly this layout.
  Eigen::SparseMatrix<double> K(dofs.n_free, n_cols);
  K.resizeNonZeros(static_cast<Eigen::Index>(col_ptr.back()));
  std::copy(col_ptr.begin(), col_ptr.end(), K.outerIndexPtr());
  int* row_idx = K.innerIndexPtr();
  double* values = K.valuePtr();
  parallel_for(n_range, [&](std::size_t lo, std::size_t hi) {
    for (std::size_t i = lo; i < hi; ++i) {
      const int v = first_node + static_cast<int>(i);
      if (n_free_of[v] == 0) continue;
      const auto& list = nbr[i];
      for (int c = 0; c < 3; ++c) {
        const int d = dofs.dof(v, c);
        if (d < 0) continue;
        Eigen::Index k = col_ptr[d - first_dof];
        for (int a : list)
          for (int r = 0; r < 3; ++r)
            if (const int row = dofs.dof(a, r); row >= 0) {
              row_idx[k] = row;
              values[k++] = 0.0;
            }
      }
      for (int k = around.first[v]; k < around.first[v + 1]; ++k) {
        const int e = around.tet[k], s = slot[e];
        const auto& t = mesh.tets[e];
        const int b = static_cast<int>(std::find(t.begin(), t.end(), v) - t.begin());
        for (int a = 0; a < 4; ++a) {
          if (n_free_of[t[a]] == 0) continue;
          const Eigen::Matrix3d block = isotropic_block(grad[s][a], grad[s][b], lame[s][0], lame[s][1], volume[s]);
          const auto j = std::lower_bound(list.begin(), list.end(), t[a]) - list.begin();
          for (int cb = 0; cb < 3; ++cb) {
            const int d = dofs.dof(v, cb);
            if (d < 0) continue;
            double* column = values + col_ptr[d - first_dof] + row_offset[i][j];
            for (int ca = 0, row = 0; ca < 3; ++ca)
              if (dofs.dof(t[a], ca) >= 0) column[row++] += block(ca, cb);
          }
        }
      }
    }
  });
  return K;
}

NodeGraph free_node_graph(const Mesh& mesh, const DofMap& dofs) {
  NodeGraph g;
  std::vector<int> vertex(dofs.n_nodes, -1);
  g.first_dof.push_back(0);
  for (int v = 0; v < dofs.n_nodes; ++v)
    if (const int k = free_components(dofs, v); k > 0) {
      vertex[v] = static_cast<int>(g.first_dof.size()) - 1;
      g.first_dof.push_back(g.first_dof.back() + k);
    }
  const NodeTets around(mesh);
  g.adj_start.push_back(0);
  std::vector<int> list;
  for (int v = 0; v < dofs.n_nodes; ++v) {
    if (vertex[v] < 0) continue;
    list.clear();
    for (int k = around.first[v]; k < around.first[v + 1]; ++k)
      for (int a : mesh.tets[around.tet[k]])
        if (vertex[a] >= 0) list.push_back(vertex[a]);
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    g.adj.insert(g.adj.end(), list.begin(), list.end());
    g.adj_start.push_back(static_cast<int>(g.adj.size()));
  }
  return g;
}

namespace {

// The body's outward unit normal on each triangle of a group, from the tetrahedron it bounds.
std::vector<Eigen::Vector3d> outward_normals(const Mesh& mesh, const std::string& group, const std::vector<int>& tris) {
  std::vector<std::array<int, 3>> faces;
  for (int t : tris) faces.push_back(mesh.triangles[t]);
  const std::vector<int> tet = tetrahedra_of_faces(mesh, faces);
  std::vector<Eigen::Vector3d> normals;
  for (std::size_t k = 0; k < tris.size(); ++k) {
    const int t = tris[k], e = tet[k];
    if (e < 0)
      throw InputError("boundary.pressure on '" + group + "': triangle " + std::to_string(mesh.triangle_tags[t]) +
                       (e == kNoTetrahedron ? " is not a face of any tetrahedron"
                                            : " is an interior face (two tetrahedra share it)") +
                       "; a pressure acts on the body's boundary");
    const auto& tri = mesh.triangles[t];
    int inner = -1;  // the tetrahedron's fourth node
    for (int v : mesh.tets[static_cast<std::size_t>(e)])
      if (std::find(tri.begin(), tri.end(), v) == tri.end()) inner = v;
    Eigen::Vector3d n =
        (mesh.nodes[tri[1]] - mesh.nodes[tri[0]]).cross(mesh.nodes[tri[2]] - mesh.nodes[tri[0]]).normalized();
    if (n.dot(mesh.nodes[inner] - mesh.nodes[tri[0]]) > 0) n = -n;
    normals.push_back(n);
  }
  return normals;
}

// Adds the loads at the nodes (3 per node) of every surface load and the body force.
Eigen::VectorXd nodal_loads(const Mesh& mesh, const std::vector<Traction>& tractions, const BodyForce& body_force) {
  Eigen::VectorXd load = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(mesh.nodes.size()));
  for (const auto& tr : tractions) {
    if (mesh.find_group(tr.group, 2) == nullptr && mesh.find_group(tr.group, 3) != nullptr)
      throw InputError("the load on '" + tr.group +
                       "' names a volume (3-D) group; tractions and pressures act on "
                       "boundary (2-D) groups");
    const std::vector<int> tris = mesh.triangles_of_group(tr.group);
    const std::vector<Eigen::Vector3d> normals =
        tr.has_pressure() ? outward_normals(mesh, tr.group, tris) : std::vector<Eigen::Vector3d>();
    for (std::size_t k = 0; k < tris.size(); ++k) {
      const auto& tri = mesh.triangles[tris[k]];
      const double area = triangle_area(mesh, tri);
      std::array<Eigen::Vector3d, 3> t;  // the traction at the corners; ∫ t φ_i = |T|/12 (2 t_i + t_j + t_k)
      for (int a = 0; a < 3; ++a) {
        const Eigen::Vector3d& x = mesh.nodes[tri[a]];
        t[a] = tr.value + tr.gradient * x;
        if (tr.has_pressure()) t[a] -= (tr.pressure + tr.pressure_gradient.dot(x)) * normals[k];
      }
      for (int a = 0; a < 3; ++a)
        load.segment<3>(3 * tri[a]) += area / 12.0 * (2 * t[a] + t[(a + 1) % 3] + t[(a + 2) % 3]);
    }
  }
  if (!body_force.is_zero())
    for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
      const auto& t = mesh.tets[e];
      const double vol = std::abs(tet_volume(coords(mesh, t)));
      for (int v : t) load.segment<3>(3 * v) += body_force[e] * (vol / 4.0);
    }
  return load;
}

}  // namespace

Eigen::VectorXd assemble_load(const Mesh& mesh, const DofMap& dofs, const std::vector<Traction>& tractions,
                              const BodyForce& body_force) {
  const Eigen::VectorXd load = nodal_loads(mesh, tractions, body_force);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dofs.n_free);
  for (Eigen::Index i = 0; i < load.size(); ++i)
    if (const int d = dofs.free_index[i]; d >= 0) f[d] += load[i];
  // Loads so large that |f|² overflows would turn every norm in the dual QP into inf/NaN.
  if (!std::isfinite(f.squaredNorm()))
    throw InputError(
        "the load vector overflows double precision (|f|² is not finite): tractions or body force too "
        "large; rescale the units");
  return f;
}

Eigen::VectorXd assemble_lift(const Mesh& mesh, const DofMap& dofs, const TetMaterials& material) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(dofs.n_free);
  if (!dofs.has_nonzero_prescribed()) return f;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const auto& t = mesh.tets[e];
    Eigen::Matrix<double, 12, 1> g;
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c) g[3 * a + c] = dofs.dof(t[a], c) < 0 ? dofs.prescribed[3 * t[a] + c] : 0.0;
    if (g.isZero(0)) continue;
    const Eigen::Matrix<double, 12, 1> Kg = element_stiffness(coords(mesh, t), hooke_matrix(material[e])) * g;
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c)
        if (const int d = dofs.dof(t[a], c); d >= 0) f[d] -= Kg[3 * a + c];
  }
  if (!std::isfinite(f.squaredNorm()))
    throw InputError(
        "the prescribed displacements overflow the load vector (|K u_c|² is not finite); rescale the units");
  return f;
}

Eigen::VectorXd internal_minus_external(const Mesh& mesh, const TetMaterials& material,
                                        const std::vector<Traction>& tractions, const BodyForce& body_force,
                                        const Eigen::VectorXd& u_nodes) {
  Eigen::VectorXd r = -nodal_loads(mesh, tractions, body_force);
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const auto& t = mesh.tets[e];
    Eigen::Matrix<double, 12, 1> ue;
    for (int a = 0; a < 4; ++a) ue.segment<3>(3 * a) = u_nodes.segment<3>(3 * t[a]);
    const Eigen::Matrix<double, 12, 1> Ku = element_stiffness(coords(mesh, t), hooke_matrix(material[e])) * ue;
    for (int a = 0; a < 4; ++a) r.segment<3>(3 * t[a]) += Ku.segment<3>(3 * a);
  }
  return r;
}

std::vector<ReactionForce> reaction_forces(const DofMap& dofs, const Eigen::VectorXd& residual) {
  std::vector<ReactionForce> out(dofs.conditions.size());
  for (std::size_t k = 0; k < out.size(); ++k) out[k].condition = dofs.conditions[k];
  for (std::size_t i = 0; i < dofs.fixed_by.size(); ++i)
    if (dofs.fixed_by[i] >= 0)
      out[dofs.fixed_by[i]].force[static_cast<int>(i % 3)] += residual[static_cast<Eigen::Index>(i)];
  return out;
}

Eigen::VectorXd expand_to_nodes(const DofMap& dofs, const Eigen::VectorXd& u_free) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * dofs.n_nodes);
  for (int i = 0; i < 3 * dofs.n_nodes; ++i)
    u[i] = dofs.free_index[i] >= 0 ? u_free[dofs.free_index[i]] : dofs.prescribed[i];
  return u;
}

}  // namespace contact3d
