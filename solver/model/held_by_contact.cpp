#include "model/held_by_contact.hpp"

#include <algorithm>
#include <array>

#include <Eigen/QR>
#include <Eigen/SVD>

#include "base/errors.hpp"
#include "base/format.hpp"

namespace contact3d {

namespace {

std::string describe_all(const FreeRigidMotions& motions) {
  std::string text;
  for (int j = 0; j < motions.count(); ++j) text += (j ? " and " : "") + motions.describe(motions.motions.col(j));
  return text;
}

}  // namespace

std::string ContactHeldMotions::describe() const { return describe_all(named); }
std::string ContactHeldMotions::describe_in_plane() const { return describe_all(in_plane); }

void ContactHeldMotions::remove_springs(const Eigen::VectorXd& w, Eigen::VectorXd& Ks_w) const {
  for (std::size_t p = 0; p < pins.size(); ++p) Ks_w[pins[p]] -= pin_springs[p] * w[pins[p]];
}

namespace {

// Of the motions (t; ω), the parts that move the plane z = 0 along its normal: t_z, ω_x, ω_y.
Eigen::Matrix<double, 3, Eigen::Dynamic> normal_parts(const FreeRigidMotions& free) {
  Eigen::Matrix<double, 3, Eigen::Dynamic> parts(3, free.count());
  parts.row(0) = free.motions.row(2);
  parts.row(1) = free.motions.row(3);
  parts.row(2) = free.motions.row(4);
  return parts;
}

// k dofs where R's rows are the best conditioned k × k block (column-pivoted QR of Rᵀ).
std::vector<int> pin_dofs(const Eigen::MatrixXd& field) {
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(field.transpose());
  std::vector<int> pins;
  for (Eigen::Index j = 0; j < field.cols(); ++j) pins.push_back(qr.colsPermutation().indices()[j]);
  return pins;
}

// The pure translations leading `motions` (no rotation part) in a basis of the user's axes where their
// span holds them, else of the directions nearest to those axes: translations free along y and z are
// named (0, 1, 0) and (0, 0, 1), not two mixtures such as (0, 0.0107, 0.99994) and (0, 0.99994, −0.0107).
void align_translations_with_axes(FreeRigidMotions& motions) {
  Eigen::Index k = 0;
  while (k < motions.count() && motions.motions.col(k).tail<3>().norm() <= 1e-9) ++k;
  if (k == 0) return;
  const Eigen::Matrix3d onto = motions.motions.topLeftCorner(3, k) * motions.motions.topLeftCorner(3, k).transpose();
  std::array<int, 3> axes = {0, 1, 2};  // the axes nearest the span first (x, y, z among equals)
  std::stable_sort(axes.begin(), axes.end(),
                   [&](int a, int b) { return onto.col(a).norm() > onto.col(b).norm() + 1e-12; });
  Eigen::Index chosen = 0;
  for (std::size_t a = 0; a < axes.size() && chosen < k; ++a) {
    Eigen::Vector3d v = onto.col(axes[a]);
    for (Eigen::Index j = 0; j < chosen; ++j)
      v -= motions.motions.col(j).head<3>().dot(v) * motions.motions.col(j).head<3>();
    if (v.norm() <= 1e-6) continue;
    motions.motions.col(chosen).head<3>() = v.normalized();
    motions.motions.col(chosen).tail<3>().setZero();
    ++chosen;
  }
}

// The motions (t; ω) about the centre, from the plane's frame into the user's global axes, in a basis
// that names well: the slides and lifts first (no rotation; along the axes where they can be), then the
// rotations orthogonal to them (their axes pass as near the centroid as the free space allows).
FreeRigidMotions in_user_frame(const FreeRigidMotions& local, const FoundationFrame& frame) {
  FreeRigidMotions global = local;
  if (local.count() > 0) {
    const Eigen::JacobiSVD<Eigen::MatrixXd> turns(local.motions.bottomRows(3), Eigen::ComputeFullV);
    const Eigen::MatrixXd by_rotation = local.motions * turns.matrixV();  // orthonormal, rotations first
    global.motions = by_rotation.rowwise().reverse();                     // translations first
  }
  global.centre = frame.to_global_point(local.centre);
  for (Eigen::Index j = 0; j < global.motions.cols(); ++j) {
    const Eigen::Matrix<double, 6, 1> motion = global.motions.col(j);
    global.motions.col(j).head<3>() = frame.to_global(motion.head<3>());
    global.motions.col(j).tail<3>() = frame.to_global(motion.tail<3>());
  }
  align_translations_with_axes(global);
  return global;
}

// A mesh of several disconnected parts (no node shared between them): the free rigid motions and the
// equalities that let the contact hold them are the whole body's, so each part must be held by its
// own prescribed components (two blocks each clamped are solved), else K is singular along that
// part's own motions and the factorization would fail with a message about Γu. Refused up front,
// naming the part and its motion, in the user's frame.
void require_each_part_held(const Mesh& mesh, const DofMap& dofs, const FoundationFrame& user_frame) {
  const BodyParts parts = body_parts(mesh);
  if (parts.count() < 2) return;
  for (int part = 0; part < parts.count(); ++part) {
    const FreeRigidMotions free = in_user_frame(free_rigid_motions(mesh, dofs, parts, part), user_frame);
    if (free.count() == 0) continue;
    const Eigen::Vector3d& c = free.centre;
    const int tets = parts.tets[static_cast<std::size_t>(part)];
    throw InputError(
        "the mesh has " + std::to_string(parts.count()) +
        " disconnected parts (no node is shared between them), and the prescribed displacements leave part " +
        std::to_string(part + 1) + " (" + count(tets) + (tets == 1 ? " tetrahedron" : " tetrahedra") +
        ", centred at (" + number(c.x(), 6) + ", " + number(c.y(), 6) + ", " + number(c.z(), 6) + ")) free to move: " +
        (free.count() == 6 ? std::string("no clamped or prescribed node lies on it, all six rigid motions are")
                           : describe_all(free) + (free.count() > 1 ? " are" : " is")) +
        " free; the contact holds a body only when its mesh is one connected part, so hold "
        "every part with boundary.clamped or boundary.displacement, join the parts into one "
        "volume (shared nodes), or solve each part as its own scene");
  }
}

}  // namespace

ContactHeldMotions contact_held_motions(const Mesh& mesh, const DofMap& dofs, bool has_contact,
                                        const FoundationFrame& user_frame) {
  require_each_part_held(mesh, dofs, user_frame);
  ContactHeldMotions held;
  held.free = free_rigid_motions(mesh, dofs);
  held.named = in_user_frame(held.free, user_frame);
  if (held.count() == 0) return held;
  if (!has_contact) require_rigid_motions_fixed(mesh, dofs);  // throws, naming the motion
  // A combination of the free motions with no normal part slides or turns the body in the plane:
  // only friction holds it.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(normal_parts(held.free), Eigen::ComputeFullV);
  const Eigen::Index k = held.count();
  Eigen::Index held_rank = 0;  // motions with a normal part
  while (held_rank < svd.singularValues().size() && svd.singularValues()[held_rank] >= 1e-6) ++held_rank;
  held.normal_combinations = svd.matrixV().leftCols(held_rank);
  if (held_rank < k) {
    held.in_plane_combinations = svd.matrixV().rightCols(k - held_rank);
    const Eigen::MatrixXd in_plane = held.free.motions * held.in_plane_combinations;
    held.in_plane = in_user_frame({in_plane, held.free.centre, held.free.size}, user_frame);
  }
  held.field = rigid_motion_field(mesh, dofs, held.free);
  held.pins = pin_dofs(held.field);
  return held;
}

void add_pin_springs(Eigen::SparseMatrix<double>& K, ContactHeldMotions& held) {
  held.pin_springs.clear();
  for (const int p : held.pins) {
    const double spring = K.coeff(p, p);
    K.coeffRef(p, p) += spring;
    held.pin_springs.push_back(spring);
  }
}

void add_pin_springs(const Mesh& mesh, const DofMap& dofs, const TetMaterials& materials, ContactHeldMotions& held) {
  held.pin_springs = stiffness_diagonal_at(mesh, dofs, materials, held.pins);
}

}  // namespace contact3d
