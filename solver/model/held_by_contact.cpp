#include "model/held_by_contact.hpp"

#include <algorithm>
#include <array>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "contact/contact_operator.hpp"
#include "contact/partition.hpp"
#include "friction/tresca_step.hpp"
#include "model/solution_checks.hpp"
#include "qp/dual_qp_solver.hpp"

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
  held.user_frame = user_frame;
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
                     "or boundary.displacement" +
                     (p.parts > 1
                          ? std::string("; if the parts were meant as one body, their volumes were meshed without "
                                        "being joined (gmsh: BooleanFragments or Coherence), and touch "
                                        "through nodes of their own")
                          : std::string()));
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

namespace {

// How many cells carry the last solve's normal force (cells_pressed; the friction of Tresca cells out of
// contact does not count either).
long pressed_cells(const Partition& partition, const TrescaStep& tresca) {
  if (tresca.history().empty()) return 0;
  return static_cast<long>(cells_pressed(tresca.history().back().lambda, partition).size());
}

// A contact face one cell wide: all its cells' centres on one line (within a tenth of a cell's side),
// so their forces have no arm about it and nothing holds a turn about that line — a bar standing on a
// face 10 mm wide with cells of 2h = 10 mm, whose balance the QP then cannot meet and whose refusal
// blamed the friction. (Pressed cells in one row of a wider face are a body the loads tip onto an
// edge: not this.) Returns the refusal's explanation, or "".
std::string face_one_cell_wide(const Partition& partition) {
  const std::size_t n = partition.cells.size();
  if (n < 2) return "";
  const double across = std::sqrt(
      std::max(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(centroid_spread(partition, {})).eigenvalues()[0], 0.0));
  const double side = std::min(partition.hx, partition.hy);
  if (!(side > 0) || across > 0.1 * side) return "";
  return "the contact face is one cell wide (its " + std::to_string(n) +
         " cells lie in one row): their forces have no arm about that row, so nothing holds a turn about it; "
         "use smaller cells (contact.cell_size, e.g. \"1.5h\") or a finer mesh there, so that the face is "
         "several cells wide, or prescribe that motion";
}

// Where the last solve pressed one or two cells, the contact cannot balance a general moment of
// the loads (its force acts at the cells' centres): said with the refusal below, with what to change.
std::string too_few_cells(const ContactOperator& op, const Partition& partition, const TrescaStep& tresca) {
  const long pressed = pressed_cells(partition, tresca);
  if (pressed == 0 || pressed >= 3) return "";  // none: the loads pull it off, said in the message
  return "; the body rests on " + std::to_string(pressed) + " of the " + std::to_string(op.r) +
         " cells of the contact partition, too few to balance the loads' moments about it (a contact zone smaller "
         "than a cell, as under a sphere): refine the mesh where it touches, or use smaller cells "
         "(contact.cell_size), so that the contact zone spans several cells. If the loads turn the body about "
         "its contact zone whatever its size (a ball or a cylinder on an incline rolls: friction at the contact "
         "and loads through the centre leave a moment), no mesh balances them: prescribe that turn "
         "(boundary.displacement) or add the load that holds it";
}

// The last solve's rigid displacement (`motions` × its multipliers), less its slide along the in-plane
// motions where friction is at its limit along them: how far the body slides there is not determined
// (any further slide solves the problem as well; warn_if_friction_at_its_limit says so), so its size
// says nothing of what the contact holds. A block pushed sideways by exactly F·N slid 33 m on one mesh,
// 5 cm on others, and the first was refused as a motion its 100 pressed cells "cannot hold".
Eigen::VectorXd determined_rigid_displacement(const ContactHeldMotions& held, const Eigen::MatrixXd& motions,
                                              const ContactOperator& op, const TrescaStep& tresca) {
  const Eigen::VectorXd rigid = motions * tresca.history().back().rigid;
  const FrictionHold hold = friction_hold(held, op, tresca);
  if (hold.share < kFrictionHoldReached) return rigid;
  return rigid - part_along(hold.slide, rigid);  // that one motion only: any other stays checked
}

}  // namespace

Eigen::VectorXd part_along(const Eigen::VectorXd& motion, const Eigen::VectorXd& rigid) {
  const double length = motion.squaredNorm();
  if (motion.size() != rigid.size() || !(length > 0)) return Eigen::VectorXd::Zero(rigid.size());
  return (motion.dot(rigid) / length) * motion;
}

// Frictionless contact leaves the in-plane motions (slides, the turn about the normal) to the loads:
// an InputError where they do not balance along them, above the QP's 1e-6 of the loads along the
// free motions for its equalities; where those loads are all in-plane and balance, what is left is
// rounding, judged against the bound ‖R‖‖f‖ (1e-9 of it: a real imbalance of 1e-6 of the load is
// 1e-7 … 1e-6 of it, the rounding of the sums 1e-14).
void require_in_plane_balance(const ContactHeldMotions& held, const Eigen::VectorXd& f,
                              const std::string& how_to_add_friction) {
  const Eigen::MatrixXd& R = held.field;
  const Eigen::VectorXd loads = R.transpose() * f;
  const Eigen::VectorXd along = held.in_plane_combinations.transpose() * loads;
  if (!(along.norm() > 1e-6 * loads.norm() + 1e-9 * R.norm() * f.norm())) return;
  throw InputError("the body is held by contact alone and nothing prescribed holds " + held.describe_in_plane() +
                   " in the foundation's plane: friction alone must hold it there, but the contact is frictionless "
                   "and the loads along it do not balance (" +
                   number(100 * along.norm() / loads.norm(), 3) +
                   "% of the loads along the free motions); prescribe that motion (boundary.displacement, e.g. "
                   "symmetry planes), " +
                   how_to_add_friction + ", or check the loads' directions");
}

// Contact forces push the body along the foundation's normal only: where nothing prescribed holds a
// part's lift (the translation along the normal), the loads on it must press it onto the plane, their
// resultant along the normal towards it. Refused here, before any factorization (the solve refused it
// after its QP, and `check` said ok), where the pull outweighs 1e-6 of the applied loads' normal
// components (their sizes summed) and 1e-9 of all their components: the loads of prescribed values
// (`f` − `applied`) add nothing along a free lift but rounding, and are large node by node (a free cube
// sheared by 1 mm let a pull of 160 N through when they counted), and where no applied load acts along
// the normal the pull is rounding (a cube against a vertical wall was refused for 1.7e-11 N).
void require_loads_press_onto_plane(const ContactHeldMotions& held, const Eigen::VectorXd& f,
                                    const Eigen::VectorXd& applied) {
  Eigen::Matrix<double, 6, 1> lift;
  lift << 0, 0, 1, 0, 0, 0;
  const double rounding = 1e-9 * applied.lpNorm<1>();
  Eigen::Index col = 0;
  for (const PartMotions& p : held.parts) {
    const Eigen::Index k = p.free.count();
    const Eigen::VectorXd along = p.free.motions.transpose() * lift;  // the motions are orthonormal
    const auto field = held.field.middleCols(col, k);
    col += k;
    if ((p.free.motions * along - lift).norm() > 1e-8) continue;  // the lift is held by a prescribed component
    const Eigen::VectorXd lift_field = field * along;             // 1 at the part's free normal components
    const double pull = lift_field.dot(f);
    const double normal_loads = lift_field.cwiseProduct(applied).cwiseAbs().sum();
    if (!(pull > 1e-6 * normal_loads + rounding)) continue;
    throw InputError(
        (p.parts > 1 ? p.label() + " is" : std::string("the body is")) +
        " held by contact alone along the foundation's normal (nothing prescribed holds its lift), and the loads "
        "pull it off the foundation: their resultant along the normal, " +
        number(pull, 4) + ", points away from the plane" +
        (normal_loads > 0
             ? " (" + number(100 * pull / normal_loads, 3) + "% of the sum of their normal components' sizes)"
             : std::string()) +
        "; the contact can only push, so nothing balances them — check the loads' directions and signs (a pressure "
        "is positive into the body, material.body_force points the way gravity pulls), or prescribe that motion "
        "(boundary.displacement)");
  }
}

void require_held(const ContactHeldMotions& held, const Eigen::MatrixXd& motions, const Eigen::VectorXd& f,
                  const ContactOperator& op, const Partition& partition, const DualQpSolver& qp,
                  const TrescaStep& tresca, bool coulomb) {
  // An inner QP that did not converge leaves the loads unbalanced whatever the friction: the run then
  // ends as the dual QP's failure (FixedPointStatus::InnerSolverFailed), not as this input error.
  const bool balanced = qp.equality_residual() <= 1e-6 && !tresca.history().empty();
  if (balanced || (!tresca.history().empty() && tresca.last_qp().status == QpStatus::Breakdown)) {
    // Balanced on one or two cells, the loads' moments lean on forces under 1e-3 of the contact's at
    // cells that barely touch, or on the friction of cells out of contact (Tresca): no answer either,
    // the nodes penetrating by many times the deformation. Only where a tilt is free: one cell holds a
    // lift, and motions in the plane lean on no moment of the normal forces (a block on one cell, its
    // top pushed down, frictionless: uniaxial compression, refused before as resting on too few cells).
    const bool tilt_is_free = held.count() - held.in_plane_count() >= 2;
    if (const std::string few = tilt_is_free ? too_few_cells(op, partition, tresca) : ""; !few.empty())
      throw ContactZoneTooCoarse("the body is held by contact alone (nothing prescribed holds " + held.describe() +
                                 ")" + few);
    // Balanced, but only after a rigid motion many times the body's size, which a linear model's
    // answer cannot be: the displacement is then rounding (a frictionless half-cylinder pressed on its
    // side, whose lateral slide was among the equalities before equality_motions(), moved along it by
    // 8e11 times its size: equilibrium residual 18, and the run said "converged").
    const double rigid = determined_rigid_displacement(held, motions, op, tresca).lpNorm<Eigen::Infinity>();
    const double size = held.size;  // the largest extent of a part held by contact
    if (!(rigid <= kLargestRigidMotion * size)) {
      // Most of that motion the face's start above the plane (its smallest cell gap, ∫d dS over the cell's
      // area)? Then that is what to change (a helper's body 1 m above the plane was told first to refine
      // the mesh).
      double lowest_gap = INFINITY;
      for (int i = 0; i < op.r; ++i)
        lowest_gap = std::min(lowest_gap, -op.offset[i] / partition.cells[static_cast<std::size_t>(i)].area);
      if (lowest_gap >= 0.5 * rigid)
        throw ContactZoneTooCoarse(
            "the body is held by contact alone (nothing prescribed holds " + held.describe() +
            ") and its contact face starts " + number(lowest_gap, 3) +
            " above the foundation plane: the loads bring it down by a rigid displacement of " + number(rigid, 3) +
            ", " + number(rigid / size, 3) +
            " times the body's size, which a linear model cannot follow; if the foundation is meant to be where the "
            "face lies, place it there (contact.plane_point, contact.plane_normal) or move the mesh, and check the "
            "mesh's units");
      throw ContactZoneTooCoarse(
          "the body is held by contact alone (nothing prescribed holds " + held.describe() +
          "), and the contact forces balance the loads only after a rigid displacement of " + number(rigid, 3) + ", " +
          number(rigid / size, 3) + " times the body's size: the " + std::to_string(pressed_cells(partition, tresca)) +
          " cells that carry the contact force cannot hold that motion (a contact zone one cell wide, "
          "as along a line contact, cannot hold a turn about it); refine the mesh where it touches, or use "
          "smaller cells (contact.cell_size), so that the contact zone spans several cells across, or "
          "prescribe that motion (boundary.displacement)");
    }
    return;
  }
  const std::size_t solves = tresca.history().size();
  // Coulomb's first solve is frictionless (every disc's radius 0): the loads along the in-plane motions
  // are left to the friction of the solves after it, so a run that stopped there failed along the
  // others, and its share of the loads left unbalanced is theirs.
  const bool frictionless_start =
      op.with_friction && solves == 1 && !(tresca.history().back().radius.array() > 0).any() && held.in_plane_count();
  double unbalanced_share = qp.equality_residual();
  // The generalized forces along the free motions that the contact leaves over, Rᵀ(𝔹ᵀλ − f).
  Eigen::VectorXd left;
  if (!tresca.history().empty()) {
    const Eigen::MatrixXd& R = held.field;
    left = (op.B * R).transpose() * tresca.history().back().lambda - R.transpose() * f;
  }
  if (frictionless_start && left.norm() > 0)
    unbalanced_share *= (held.normal_combinations.transpose() * left).norm() / left.norm();
  const std::string in_solve = solves > 1 ? " in solve " + std::to_string(solves) +
                                                " of the successive approximations, "
                                                "with its slips' friction coefficients"
                               : frictionless_start
                                   ? " along the motions with a normal part in the first solve, the frictionless one "
                                     "that gives Coulomb's first normal pressure"
                                   : "";
  const std::string unbalanced = number(100 * unbalanced_share, 3) + "% of them left unbalanced" + in_solve;
  // On one or two pressed cells the cure may be smaller cells: thrown as ContactZoneTooCoarse, so that
  // contact.cell_size = "auto" tries cells of 1.5h before refusing (a ball resting on two cells).
  // The same where the face is one cell wide and a tilt is among the free motions (beside the lift).
  std::string few = too_few_cells(op, partition, tresca);
  if (few.empty() && held.count() - held.in_plane_count() >= 2)
    if (const std::string row = face_one_cell_wide(partition); !row.empty()) few = "; " + row;
  // A partition of one or two cells over the whole face (a cell size in the wrong unit) is the cause to
  // name first: its one force at the cell's centre holds no turn, whatever the friction (a washer under
  // a pressure that is symmetric up to rounding was refused for loads "more than the friction carries").
  const std::string whole_face =
      op.r <= 2 ? "the contact partition has only " + std::to_string(op.r) +
                      " cell(s) over the whole contact face (contact.cell_size), too few for contact forces to hold "
                      "the body: "
                : "";
  auto refuse = [&few, &whole_face](const std::string& message) {
    if (few.empty()) throw InputError(message);
    throw ContactZoneTooCoarse(whole_face + message + few);
  };
  if (held.in_plane_count() && !tresca.history().empty() && !frictionless_start) {
    // The share of the in-plane loads (the tangential force and the torque about the normal) left
    // over, not of all loads: a torque 30% beyond what friction carries, beside a large normal
    // load, read "4.55% of them left unbalanced".
    const Eigen::VectorXd left_in_plane = held.in_plane_combinations.transpose() * left;
    const Eigen::VectorXd loads_in_plane = held.in_plane_combinations.transpose() * (held.field.transpose() * f);
    const char* const them = held.in_plane_count() > 1 ? "them" : "it";
    const std::string in_plane_unbalanced = loads_in_plane.norm() > 0
                                                ? number(100 * left_in_plane.norm() / loads_in_plane.norm(), 3) +
                                                      "% of the loads along " + them + " left unbalanced" + in_solve
                                                : unbalanced;
    // What sets the friction the run had: Coulomb's coefficient alone, or Tresca's bound g with it.
    const std::string friction_keys =
        coulomb ? "the coefficient: friction.value or the law's values; with model = \"coulomb\" the bound is F "
                  "times the normal pressure"
                : "friction.slip_bound, the coefficient, friction.model";
    if (left_in_plane.norm() > 0.5 * left.norm())
      refuse("the body is held by contact alone and nothing prescribed holds " + held.describe_in_plane() +
             " in the foundation's plane: friction alone must hold it there, but the loads along " + them +
             " are more than the contact's friction carries (" + in_plane_unbalanced + ")" +
             (op.with_friction ? "" : ", the contact being frictionless") +
             ": the body would slide on the foundation, which a static solve has no answer for; prescribe that "
             "motion (boundary.displacement, e.g. symmetry planes) or check the friction (" +
             friction_keys + ") and the loads' directions");
  }
  // No cell presses at all: the loads lift the whole body off (a pull on its top, as plain as that),
  // said before the list of causes that fit a body that does touch.
  if (!tresca.history().empty() && pressed_cells(partition, tresca) == 0)
    refuse("the body is held by contact alone (nothing prescribed holds " + held.describe() +
           "), and the loads lift it off the foundation: no cell presses (" + unbalanced +
           "); the contact can only push, so loads that pull the body off the plane have nothing to balance "
           "them — check the loads' directions and signs (a pressure is positive into the "
           "body), or prescribe that motion (boundary.displacement)");
  refuse("the body is held by contact alone (nothing prescribed holds " + held.describe() +
         "), but no contact forces balance the loads along it (" + unbalanced +
         "): the loads pull the body off the foundation or tip it over an edge of the "
         "contact face, or it touches the foundation on too few cells to balance their moments (a "
         "contact zone smaller than a few cells, as under a sphere); prescribe that motion, check the "
         "loads' directions, or refine the mesh where it touches");
}

namespace {

using CellMotions = std::vector<Eigen::Matrix<double, 2, Eigen::Dynamic>>;  // per cell, 2 × q

// Σ_i c_i ‖V_i a‖: the most work friction bounded by the radii c can do along the motion a.
double most_friction_work(const CellMotions& V, const Eigen::VectorXd& c, const Eigen::VectorXd& a) {
  double sum = 0;
  for (std::size_t i = 0; i < V.size(); ++i) sum += c[static_cast<Eigen::Index>(i)] * (V[i] * a).norm();
  return sum;
}

// min Σ_i c_i ‖V_i a‖ subject to bᵀa = 1 (V_i: 2 × q, the in-plane motions' tangential motion of cell
// i): iteratively reweighted least squares, each step the minimiser of Σ w_i ‖V_i a‖² on the constraint
// with w_i = c_i / ‖V_i a‖ of the step before (monotone, as Weiszfeld's). Returns the minimum's a.
Eigen::VectorXd least_friction_work(const CellMotions& V, const Eigen::VectorXd& c, const Eigen::VectorXd& b) {
  const Eigen::Index q = b.size();
  Eigen::VectorXd a = b / b.squaredNorm();
  double value = most_friction_work(V, c, a);
  for (int step = 0; step < 200; ++step) {
    const double floor = 1e-12 * a.norm();  // a cell the motion barely moves keeps a finite weight
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(q, q);
    for (std::size_t i = 0; i < V.size(); ++i) {
      const double moved = std::max((V[i] * a).norm(), floor);
      M += (c[static_cast<Eigen::Index>(i)] / moved) * V[i].transpose() * V[i];
    }
    const Eigen::VectorXd Mb = M.completeOrthogonalDecomposition().solve(b);
    if (!(b.dot(Mb) > 0)) break;
    const Eigen::VectorXd next = Mb / b.dot(Mb);
    const double next_value = most_friction_work(V, c, next);
    if (!(next_value < value)) break;
    const bool settled = value - next_value <= 1e-12 * value;
    a = next, value = next_value;
    if (settled) break;
  }
  return a;
}

// The in-plane combination `a` (coefficients of held.in_plane_combinations' columns) as one motion of
// the part it moves most, named in the user's axes.
std::string name_in_plane_motion(const ContactHeldMotions& held, const Eigen::VectorXd& a) {
  const Eigen::VectorXd coefficients = held.in_plane_combinations * a;  // of the free motions, all parts
  std::size_t best = 0;
  Eigen::Index col = 0, best_col = 0;  // each part's coefficients follow the parts before it
  for (std::size_t p = 0; p < held.parts.size(); ++p) {
    const Eigen::Index k = held.parts[p].free.count();
    if (coefficients.segment(col, k).norm() > coefficients.segment(best_col, held.parts[best].free.count()).norm())
      best = p, best_col = col;
    col += k;
  }
  const PartMotions& part = held.parts[best];
  Eigen::Matrix<double, 6, 1> local = part.free.motions * coefficients.segment(best_col, part.free.count());
  // A turn whose motion across the part is under 1e-3 of the slide's is the slide, not a rotation about an
  // axis a thousand sizes away (an incline's limit was named a turn about an axis 581 km off: the
  // least-squares minimum carries such a remainder).
  if (local.tail<3>().norm() <= 1e-3 * local.head<3>().norm()) local.tail<3>().setZero();
  Eigen::Matrix<double, 6, 1> global;
  global << held.user_frame.to_global(local.head<3>()), held.user_frame.to_global(local.tail<3>());
  const std::string label = part.label();
  return (label.empty() ? "" : label + ": ") + part.named.describe(global);
}

}  // namespace

FrictionHold friction_hold(const ContactHeldMotions& held, const ContactOperator& op, const TrescaStep& tresca) {
  FrictionHold hold;
  if (!op.with_friction || held.in_plane_count() == 0 || tresca.history().empty()) return hold;
  const Eigen::VectorXd& lambda = tresca.history().back().lambda;
  const Eigen::VectorXd& radius = tresca.history().back().radius;
  const Eigen::MatrixXd moved = op.B * (held.field * held.in_plane_combinations);  // rows: multipliers
  const MultiplierLayout layout = op.layout();
  CellMotions V(static_cast<std::size_t>(op.r));
  Eigen::VectorXd b = Eigen::VectorXd::Zero(held.in_plane_count());  // Σ V_iᵀ λ_t,i
  for (int i = 0; i < op.r; ++i) {
    Eigen::Matrix<double, 2, Eigen::Dynamic>& Vi = V[static_cast<std::size_t>(i)];
    Vi.resize(2, held.in_plane_count());
    Vi.row(0) = moved.row(layout.t1(i));
    Vi.row(1) = moved.row(layout.t2(i));
    b += Vi.transpose() * Eigen::Vector2d(lambda[layout.t1(i)], lambda[layout.t2(i)]);
  }
  if (!(b.norm() > 0) || !(radius.maxCoeff() > 0)) return hold;
  const Eigen::VectorXd a = least_friction_work(V, radius, b);
  // bᵀa = 1: the loads' work along a is 1, the most friction can do along it this.
  hold.share = std::min(1.0, 1.0 / most_friction_work(V, radius, a));
  hold.motion = name_in_plane_motion(held, a);
  hold.slide = held.field * (held.in_plane_combinations * a);
  return hold;
}

}  // namespace contact3d
