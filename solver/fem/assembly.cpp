#include "fem/assembly.hpp"

#include <cmath>

#include "io/errors.hpp"

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

Eigen::SparseMatrix<double> assemble_stiffness(const Mesh& mesh, const DofMap& dofs,
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
