#include "fem/dof_map.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "base/errors.hpp"
#include "base/format.hpp"

namespace contact3d {
namespace {

const char* const kAxis[3] = {"x", "y", "z"};

std::string where(const Mesh& mesh, int v) {
  const auto& p = mesh.nodes[v];
  return "node " + std::to_string(mesh.node_tags[v]) + " (" + number(p.x()) + ", " + number(p.y()) + ", " +
         number(p.z()) + ")";
}

// "(x, y, z)" with components below 1e-9·scale (rounding noise) shown as 0.
std::string vector_text(const Eigen::Vector3d& v, double scale = 1) {
  auto c = [&](double x) { return number(std::abs(x) < 1e-9 * scale ? 0.0 : x); };
  return "(" + c(v.x()) + ", " + c(v.y()) + ", " + c(v.z()) + ")";
}

}  // namespace

bool DofMap::has_nonzero_prescribed() const {
  for (double g : prescribed)
    if (g != 0) return true;
  return false;
}

DofMap make_dof_map(const Mesh& mesh, const std::vector<std::string>& clamped_groups,
                    const std::vector<PrescribedDisplacement>& displacements) {
  DofMap map;
  map.n_nodes = static_cast<int>(mesh.nodes.size());
  map.fixed.assign(map.n_nodes, 0);
  map.prescribed.assign(3 * map.n_nodes, 0.0);
  map.fixed_by.assign(3 * map.n_nodes, -1);
  // Rounding of each value as evaluated (an affine field's terms), so that two conditions giving one
  // node the same field in different forms agree; a constant is exact.
  std::vector<double> rounding(3 * map.n_nodes, 0.0);
  auto prescribe = [&](int v, int c, double value, double value_rounding) {
    const int i = 3 * v + c;
    if (map.fixed_by[i] >= 0) {
      if (std::abs(map.prescribed[i] - value) > std::max(rounding[i], value_rounding))
        throw InputError("u_" + std::string(kAxis[c]) + " at " + where(mesh, v) +
                         " is prescribed twice with different values: " + number(map.prescribed[i]) + " by " +
                         map.conditions[map.fixed_by[i]] + " and " + number(value) + " by " + map.conditions.back());
      return;
    }
    map.fixed[v] |= static_cast<unsigned char>(1u << c);
    map.prescribed[i] = value;
    rounding[i] = value_rounding;
    map.fixed_by[i] = static_cast<int>(map.conditions.size()) - 1;
  };
  for (const auto& name : clamped_groups) {
    map.conditions.push_back("boundary.clamped '" + name + "'");
    for (int t : mesh.triangles_of_group(name))
      for (int v : mesh.triangles[t])
        for (int c = 0; c < 3; ++c) prescribe(v, c, 0.0, 0.0);
  }
  for (const auto& d : displacements) {
    map.conditions.push_back("boundary.displacement '" + d.group + "'");
    for (int t : mesh.triangles_of_group(d.group))
      for (int v : mesh.triangles[t])
        for (int c = 0; c < 3; ++c)
          if (d.value[c]) {
            const Eigen::Vector3d& x = mesh.nodes[v];
            const double terms = std::abs(*d.value[c]) + d.gradient.row(c).cwiseAbs().dot(x.cwiseAbs());
            prescribe(v, c, d.at(c, x), d.gradient.row(c).isZero() ? 0.0 : 1e-12 * terms);
          }
  }
  // Nodes not used by any tet carry no stiffness: treat them as fixed so K stays regular.
  map.used.assign(map.n_nodes, 0);
  for (const auto& t : mesh.tets)
    for (int v : t) map.used[v] = 1;
  map.free_index.assign(3 * map.n_nodes, -1);
  for (int v = 0; v < map.n_nodes; ++v)
    for (int c = 0; c < 3; ++c)
      if (map.used[v] && !(map.fixed[v] >> c & 1)) map.free_index[3 * v + c] = map.n_free++;
  return map;
}

namespace {

// The centroid and size of the nodes the tets use: rigid motions are written about the centroid
// in coordinates scaled by the size, so that translations and rotations weigh alike.
struct BodyFrame {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double size = 1;
  int n_used = 0;
  Eigen::Vector3d scaled(const Eigen::Vector3d& x) const { return (x - centre) / size; }
};

// The nodes a frame or a Gram matrix counts: every used node, or those of one part.
struct NodeSelection {
  const BodyParts* parts = nullptr;
  int part = 0;
  bool operator()(const DofMap& dofs, int v) const {
    return dofs.used[v] && (!parts || parts->of_node[static_cast<std::size_t>(v)] == part);
  }
};

BodyFrame body_frame(const Mesh& mesh, const DofMap& dofs, NodeSelection selected = {}) {
  BodyFrame f;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (int v = 0; v < dofs.n_nodes; ++v)
    if (selected(dofs, v)) {
      lo = lo.cwiseMin(mesh.nodes[v]);
      hi = hi.cwiseMax(mesh.nodes[v]);
      f.centre += mesh.nodes[v];
      ++f.n_used;
    }
  if (f.n_used == 0) return f;
  f.centre /= f.n_used;
  f.size = std::max((hi - lo).maxCoeff(), 1e-300);
  return f;
}

// Row c: component c of the six rigid motions at the scaled point x (translations e_c, then the
// rotations e_a × x).
Eigen::Matrix<double, 3, 6> rigid_motion_basis(const Eigen::Vector3d& x) {
  return (Eigen::Matrix<double, 3, 6>() << 1, 0, 0, 0, x.z(), -x.y(),  //
          0, 1, 0, -x.z(), 0, x.x(),                                   //
          0, 0, 1, x.y(), -x.x(), 0)
      .finished();
}

}  // namespace

Eigen::MatrixXd rigid_body_modes(const Mesh& mesh, const DofMap& dofs) {
  const BodyFrame frame = body_frame(mesh, dofs);
  Eigen::MatrixXd modes = Eigen::MatrixXd::Zero(dofs.n_free, 6);
  for (int v = 0; v < dofs.n_nodes; ++v) {
    if (!dofs.used[v]) continue;
    const Eigen::Matrix<double, 3, 6> basis = rigid_motion_basis(frame.scaled(mesh.nodes[v]));
    for (int c = 0; c < 3; ++c)
      if (const int d = dofs.dof(v, c); d >= 0) modes.row(d) = basis.row(c);
  }
  if (dofs.n_free < 6) return modes;
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(modes);
  return qr.householderQ() * Eigen::MatrixXd::Identity(dofs.n_free, 6);
}

namespace {

// The prescribed components' rows of the rigid motions (t; ω) in `frame`: their Gram matrix, its
// eigen-decomposition, and which eigenvalues are negligible (the motions those rows leave free), and
// Σ rowᵀ · prescribed value — shared by free_rigid_motions and prescribed_rigid_motion, so that the fit
// leaves out exactly the motions reported free.
struct PrescribedRows {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig;
  Eigen::Matrix<double, 6, 1> moment = Eigen::Matrix<double, 6, 1>::Zero();
  bool negligible(int j) const { return eig.eigenvalues()[j] <= 1e-10 * std::max(eig.eigenvalues()[5], 1.0); }
};

PrescribedRows prescribed_rows(const Mesh& mesh, const DofMap& dofs, const BodyFrame& frame,
                               NodeSelection selected = {}) {
  PrescribedRows rows;
  Eigen::Matrix<double, 6, 6> gram = Eigen::Matrix<double, 6, 6>::Zero();
  for (int v = 0; v < dofs.n_nodes; ++v) {
    if (!selected(dofs, v) || !dofs.fixed[v]) continue;
    const Eigen::Matrix<double, 3, 6> basis = rigid_motion_basis(frame.scaled(mesh.nodes[v]));
    for (int c = 0; c < 3; ++c)
      if (dofs.fixed[v] >> c & 1) {
        gram += basis.row(c).transpose() * basis.row(c);
        rows.moment += basis.row(c).transpose() * dofs.prescribed[static_cast<std::size_t>(3 * v + c)];
      }
  }
  rows.eig.compute(gram);
  return rows;
}

}  // namespace

Eigen::VectorXd prescribed_rigid_motion(const Mesh& mesh, const DofMap& dofs) {
  Eigen::VectorXd field = Eigen::VectorXd::Zero(3 * dofs.n_nodes);
  if (!dofs.has_nonzero_prescribed()) return field;
  const BodyFrame frame = body_frame(mesh, dofs);
  const PrescribedRows rows = prescribed_rows(mesh, dofs, frame);
  // Least squares of minimal norm: nothing along the motions the prescribed components leave free.
  Eigen::Matrix<double, 6, 1> motion = Eigen::Matrix<double, 6, 1>::Zero();
  for (int j = 0; j < 6; ++j)
    if (!rows.negligible(j))
      motion += rows.eig.eigenvectors().col(j) *
                (rows.eig.eigenvectors().col(j).dot(rows.moment) / rows.eig.eigenvalues()[j]);
  for (int v = 0; v < dofs.n_nodes; ++v)
    if (dofs.used[v]) field.segment<3>(3 * v) = rigid_motion_basis(frame.scaled(mesh.nodes[v])) * motion;
  return field;
}

namespace {

// A rigid motion is free iff it vanishes at every prescribed component: with coordinates scaled
// by the body's size, the Gram matrix of those components' rows is singular exactly along it.
FreeRigidMotions free_rigid_motions_of(const Mesh& mesh, const DofMap& dofs, NodeSelection selected) {
  const BodyFrame frame = body_frame(mesh, dofs, selected);
  FreeRigidMotions free;
  free.centre = frame.centre;
  free.size = frame.size;
  free.motions.resize(6, 0);
  if (frame.n_used == 0) return free;
  const PrescribedRows rows = prescribed_rows(mesh, dofs, frame, selected);
  int k = 0;
  while (k < 6 && rows.negligible(k)) ++k;
  free.motions = rows.eig.eigenvectors().leftCols(k);
  return free;
}

}  // namespace

FreeRigidMotions free_rigid_motions(const Mesh& mesh, const DofMap& dofs) {
  return free_rigid_motions_of(mesh, dofs, {});
}

FreeRigidMotions free_rigid_motions(const Mesh& mesh, const DofMap& dofs, const BodyParts& parts, int part) {
  return free_rigid_motions_of(mesh, dofs, {&parts, part});
}

namespace {

// Blocks beyond this many are not searched for joints (the kernel's Gram matrix is 6 × blocks square).
constexpr int kMostBlocksSearched = 200;

}  // namespace

std::string find_mechanism(const Mesh& mesh, const DofMap& dofs, const BodyParts& parts) {
  int blocks = 0;
  const std::vector<int> block_of_tet = face_connected_blocks(mesh, blocks);
  if (blocks <= parts.count() || blocks > kMostBlocksSearched) return "";
  const std::vector<std::vector<int>> blocks_of_node = blocks_of_nodes(mesh, block_of_tet);
  // K's zero-energy motions: a rigid motion per block, equal where blocks share a node, zero along the
  // prescribed components: the kernel of the Gram matrix of those conditions.
  const BodyFrame frame = body_frame(mesh, dofs);
  const int k = 6 * blocks;
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(k, k);
  for (int v = 0; v < dofs.n_nodes; ++v) {
    const std::vector<int>& in = blocks_of_node[static_cast<std::size_t>(v)];
    if (in.empty()) continue;
    const Eigen::Matrix<double, 3, 6> basis = rigid_motion_basis(frame.scaled(mesh.nodes[v]));
    const Eigen::Matrix<double, 6, 6> joined = basis.transpose() * basis;  // m_a(x) = m_b(x), all three components
    for (std::size_t j = 1; j < in.size(); ++j) {
      const int a = 6 * in[0], b = 6 * in[j];
      gram.block<6, 6>(a, a) += joined;
      gram.block<6, 6>(b, b) += joined;
      gram.block<6, 6>(a, b) -= joined;
      gram.block<6, 6>(b, a) -= joined;
    }
    for (int c = 0; c < 3; ++c)
      if (dofs.fixed[v] >> c & 1)
        for (const int b : in) gram.block<6, 6>(6 * b, 6 * b) += basis.row(c).transpose() * basis.row(c);
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(gram);
  const double largest = std::max(eig.eigenvalues()[k - 1], 1.0);
  int kernel = 0;
  while (kernel < k && eig.eigenvalues()[kernel] <= 1e-10 * largest) ++kernel;
  int rigid = 0;  // of which each part's own rigid motions
  for (int part = 0; part < parts.count(); ++part) rigid += free_rigid_motions(mesh, dofs, parts, part).count();
  if (kernel <= rigid) return "";
  // Name a block joined to the others at nodes that lie on one line (a hinge) or at one node.
  std::vector<std::vector<int>> joints_of_block(static_cast<std::size_t>(blocks));
  for (int v = 0; v < dofs.n_nodes; ++v)
    if (const std::vector<int>& in = blocks_of_node[static_cast<std::size_t>(v)]; in.size() > 1)
      for (const int b : in) joints_of_block[static_cast<std::size_t>(b)].push_back(v);
  for (int b = 0; b < blocks; ++b) {
    const std::vector<int>& joints = joints_of_block[static_cast<std::size_t>(b)];
    if (joints.empty()) continue;
    const Eigen::Vector3d a = mesh.nodes[static_cast<std::size_t>(joints.front())];
    Eigen::Vector3d far = a;
    for (const int v : joints)
      if ((mesh.nodes[static_cast<std::size_t>(v)] - a).norm() > (far - a).norm())
        far = mesh.nodes[static_cast<std::size_t>(v)];
    bool on_line = true;
    const Eigen::Vector3d axis =
        (far - a).norm() > 0 ? Eigen::Vector3d((far - a).normalized()) : Eigen::Vector3d::Zero();
    for (const int v : joints) {
      const Eigen::Vector3d d = mesh.nodes[static_cast<std::size_t>(v)] - a;
      on_line = on_line && (d - d.dot(axis) * axis).norm() <= 1e-9 * frame.size;
    }
    if (!on_line) continue;
    const long tets = std::count(block_of_tet.begin(), block_of_tet.end(), b);
    const std::string joint =
        joints.size() == 1 || (far - a).norm() == 0
            ? "only at the node " + vector_text(a, frame.size) + ", a ball joint about which it can turn"
            : "only along the line from " + vector_text(a, frame.size) + " to " + vector_text(far, frame.size) + " (" +
                  std::to_string(joints.size()) + " nodes, no shared face), a hinge about which it can turn";
    return "a block of " + count(tets) + (tets == 1 ? " tetrahedron" : " tetrahedra") +
           " is joined to the rest of the mesh " + joint;
  }
  return "the mesh's tetrahedra form " + std::to_string(blocks) +
         " blocks joined to each other only at nodes or along edges (no shared face), which can move against each "
         "other";
}

std::string FreeRigidMotions::describe(const Eigen::Matrix<double, 6, 1>& free_motion) const {
  // A free motion is free either way: named with its direction's largest component positive.
  const bool turns = free_motion.tail<3>().norm() >= 1e-6 * free_motion.head<3>().norm();
  const Eigen::Vector3d direction = turns ? free_motion.tail<3>() : free_motion.head<3>();
  Eigen::Index largest = 0;
  direction.cwiseAbs().maxCoeff(&largest);
  const double sign = direction[largest] < 0 ? -1.0 : 1.0;
  const Eigen::Matrix<double, 6, 1> motion = sign * free_motion;
  const Eigen::Vector3d t = motion.head<3>(), w = motion.tail<3>();
  if (w.norm() < 1e-6 * t.norm()) return "a translation along " + vector_text(t.normalized());
  // The axis of u = t + ω × (x − x̄), scaled back: points p with u(p) ∥ ω.
  const Eigen::Vector3d point = centre + size * w.cross(t) / w.squaredNorm();
  std::string what =
      "a rotation about the axis along " + vector_text(w.normalized()) + " through " + vector_text(point, size);
  if (std::abs(t.dot(w)) > 1e-6 * t.norm() * w.norm()) what += " (with a slide along it)";
  return what;
}

namespace {

Eigen::MatrixXd rigid_motion_field_of(const Mesh& mesh, const DofMap& dofs, const FreeRigidMotions& free,
                                      NodeSelection selected) {
  Eigen::MatrixXd field = Eigen::MatrixXd::Zero(dofs.n_free, free.count());
  for (int v = 0; v < dofs.n_nodes; ++v) {
    if (!selected(dofs, v)) continue;
    const Eigen::Matrix<double, 3, 6> basis = rigid_motion_basis((mesh.nodes[v] - free.centre) / free.size);
    for (int c = 0; c < 3; ++c)
      if (const int d = dofs.dof(v, c); d >= 0) field.row(d) = basis.row(c) * free.motions;
  }
  return field;
}

}  // namespace

Eigen::MatrixXd rigid_motion_field(const Mesh& mesh, const DofMap& dofs, const FreeRigidMotions& free) {
  return rigid_motion_field_of(mesh, dofs, free, {});
}

Eigen::MatrixXd rigid_motion_field(const Mesh& mesh, const DofMap& dofs, const FreeRigidMotions& free,
                                   const BodyParts& parts, int part) {
  return rigid_motion_field_of(mesh, dofs, free, {&parts, part});
}

void require_rigid_motions_fixed(const Mesh& mesh, const DofMap& dofs) {
  const FreeRigidMotions free = free_rigid_motions(mesh, dofs);
  if (free.count() == 0) return;
  throw InputError("the prescribed displacements leave the body free to move: " + free.describe(free.motions.col(0)) +
                   " is not prevented by boundary.clamped or boundary.displacement, so the stiffness matrix is "
                   "singular (the scene has no contact face that could hold it); constrain more components or groups");
}

}  // namespace contact3d
