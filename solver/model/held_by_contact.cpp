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

std::string PartMotions::label() const {
  if (parts < 2) return "";
  const Eigen::Vector3d& c = named.centre;
  return "part " + std::to_string(part + 1) + " of " + std::to_string(parts) + " (" + count(tets) +
         (tets == 1 ? " tetrahedron" : " tetrahedra") + ", centred at (" + number(c.x(), 6) + ", " + number(c.y(), 6) +
         ", " + number(c.z(), 6) + "))";
}

namespace {

// "part 2 of 3 (…): a translation along … and …" (or "…: all six rigid motions"), or the motions
// alone for a one-part body.
std::string labelled(const PartMotions& p, const FreeRigidMotions& motions) {
  if (p.parts < 2) return describe_all(motions);
  return p.label() + ": " + (motions.count() == 6 ? std::string("all six rigid motions") : describe_all(motions));
}

// The parts' motions joined by "; ", the first kNamedParts of them in full and the rest by their numbers
// (a mesh of many loose pieces would otherwise give a note of kilobytes).
constexpr std::size_t kNamedParts = 4;
template <class MotionsOf>
std::string describe_parts(const std::vector<PartMotions>& parts, MotionsOf motions_of) {
  std::string text, more;
  std::size_t named = 0, rest = 0;
  for (const PartMotions& p : parts) {
    const FreeRigidMotions& motions = motions_of(p);
    if (motions.count() == 0) continue;
    if (named < kNamedParts) {
      text += (named++ ? "; " : "") + labelled(p, motions);
    } else {
      more += (rest++ ? ", " : "") + std::to_string(p.part + 1);
    }
  }
  if (rest)
    text += "; and " + std::to_string(rest) + (rest > 1 ? " more parts (numbers " : " more part (number ") + more + ")";
  return text;
}

}  // namespace

std::string ContactHeldMotions::describe() const {
  return describe_parts(parts, [](const PartMotions& p) -> const FreeRigidMotions& { return p.named; });
}

std::string ContactHeldMotions::describe_in_plane() const {
  return describe_parts(parts, [](const PartMotions& p) -> const FreeRigidMotions& { return p.in_plane; });
}

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

// Without a contact face nothing can hold a free motion: each part of the mesh must be held by its
// own prescribed components (two blocks each clamped are solved), else K is singular along that part's
// motions and the factorization would fail with a message about Γu. Refused up front, naming the part
// and its motion, in the user's frame.
void require_each_part_held(const Mesh& mesh, const DofMap& dofs, const BodyParts& parts,
                            const FoundationFrame& user_frame) {
  for (int part = 0; part < parts.count(); ++part) {
    PartMotions p{part, parts.count(), parts.tets[static_cast<std::size_t>(part)], {}, {}, {}};
    p.named = in_user_frame(free_rigid_motions(mesh, dofs, parts, part), user_frame);
    if (p.named.count() == 0) continue;
    throw InputError("the mesh has " + std::to_string(parts.count()) +
                     " disconnected parts (no node is shared between them), and the prescribed displacements leave " +
                     p.label() + ": " +
                     (p.named.count() == 6 ? std::string("no clamped or prescribed node lies on it, all six rigid "
                                                         "motions are")
                                           : describe_all(p.named) + (p.named.count() > 1 ? " are" : " is")) +
                     " free, and the scene has no contact face that could hold it; hold every part with "
                     "boundary.clamped or boundary.displacement, or give the scene a contact face (boundary.contact) "
                     "under each part that is free");
  }
}

// One part's free motions (those of the whole body when the mesh is one part), split into those
// with a normal part and those in the plane; `field` its motions at the free dofs.
PartMotions part_motions(const Mesh& mesh, const DofMap& dofs, const BodyParts& parts, int part,
                         const FoundationFrame& user_frame, Eigen::MatrixXd& field, Eigen::MatrixXd& normal,
                         Eigen::MatrixXd& in_plane) {
  const bool whole = parts.count() == 1;
  PartMotions p{part, parts.count(), parts.tets[static_cast<std::size_t>(part)], {}, {}, {}};
  p.free = whole ? free_rigid_motions(mesh, dofs) : free_rigid_motions(mesh, dofs, parts, part);
  p.named = in_user_frame(p.free, user_frame);
  if (p.free.count() == 0) return p;
  // A combination of the free motions with no normal part slides or turns the part in the plane:
  // only friction holds it.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(normal_parts(p.free), Eigen::ComputeFullV);
  const Eigen::Index k = p.free.count();
  Eigen::Index held_rank = 0;  // motions with a normal part
  while (held_rank < svd.singularValues().size() && svd.singularValues()[held_rank] >= 1e-6) ++held_rank;
  normal = svd.matrixV().leftCols(held_rank);
  in_plane = svd.matrixV().rightCols(k - held_rank);
  if (held_rank < k) p.in_plane = in_user_frame({p.free.motions * in_plane, p.free.centre, p.free.size}, user_frame);
  field = whole ? rigid_motion_field(mesh, dofs, p.free) : rigid_motion_field(mesh, dofs, p.free, parts, part);
  return p;
}

// The k × (Σ columns) matrix with the blocks on its diagonal, in order.
Eigen::MatrixXd block_diagonal(const std::vector<Eigen::MatrixXd>& blocks) {
  Eigen::Index rows = 0, cols = 0;
  for (const Eigen::MatrixXd& b : blocks) rows += b.rows(), cols += b.cols();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(rows, cols);
  rows = cols = 0;
  for (const Eigen::MatrixXd& b : blocks) {
    out.block(rows, cols, b.rows(), b.cols()) = b;
    rows += b.rows(), cols += b.cols();
  }
  return out;
}

}  // namespace

ContactHeldMotions contact_held_motions(const Mesh& mesh, const DofMap& dofs, bool has_contact,
                                        const FoundationFrame& user_frame) {
  const BodyParts parts = body_parts(mesh);
  if (const std::string joint = find_mechanism(mesh, dofs, parts); !joint.empty())
    throw InputError(joint +
                     ", and nothing prescribed holds that motion: the stiffness matrix is singular along it (no "
                     "strain, no force); join the block to the rest through a face (shared triangles, as gmsh's "
                     "BooleanFragments gives where volumes touch over an area), or prescribe that motion");
  if (!has_contact) {
    if (parts.count() > 1) require_each_part_held(mesh, dofs, parts, user_frame);
    require_rigid_motions_fixed(mesh, dofs);  // throws, naming the motion
    return {};
  }
  ContactHeldMotions held;
  std::vector<Eigen::MatrixXd> fields, normal, in_plane;
  for (int part = 0; part < parts.count(); ++part) {
    Eigen::MatrixXd field, normal_p, in_plane_p;
    PartMotions p = part_motions(mesh, dofs, parts, part, user_frame, field, normal_p, in_plane_p);
    if (p.free.count() == 0) continue;
    held.size = held.parts.empty() ? p.free.size : std::max(held.size, p.free.size);
    held.parts.push_back(std::move(p));
    fields.push_back(std::move(field));
    normal.push_back(std::move(normal_p));
    in_plane.push_back(std::move(in_plane_p));
  }
  if (held.parts.empty()) return held;
  held.normal_combinations = block_diagonal(normal);
  held.in_plane_combinations = block_diagonal(in_plane);
  held.field.resize(dofs.n_free, held.normal_combinations.rows());
  Eigen::Index col = 0;
  for (const Eigen::MatrixXd& f : fields) {
    held.field.middleCols(col, f.cols()) = f;
    col += f.cols();
    const std::vector<int> pins = pin_dofs(f);  // each part's own: k_p² n work, not (Σ k_p)² n
    held.pins.insert(held.pins.end(), pins.begin(), pins.end());
  }
  return held;
}

void require_free_parts_on_contact_face(const ContactHeldMotions& held, const std::vector<int>& face_dofs) {
  Eigen::Index col = 0;
  for (const PartMotions& p : held.parts) {
    double on_face = 0;
    for (const int d : face_dofs) on_face = std::max(on_face, held.field.row(d).segment(col, p.free.count()).norm());
    col += p.free.count();
    if (on_face > 0) continue;
    throw InputError((p.parts > 1 ? p.label() : std::string("the body")) +
                     " has no free node on the contact face Γc, so the contact cannot hold it, and nothing prescribed "
                     "holds " +
                     (p.named.count() == 6 ? std::string("any of its six rigid motions") : describe_all(p.named)) +
                     ": put its face towards the foundation into boundary.contact, or hold it with boundary.clamped "
                     "or boundary.displacement");
  }
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
