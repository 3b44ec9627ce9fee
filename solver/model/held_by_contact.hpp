// Bodies held by contact alone (a block pressed onto the foundation with symmetry rollers and no
// clamp, a gasket under pressure): the rigid motions the prescribed components leave free are
// held by the contact forces, as in FETI's treatment of floating subdomains. K is singular along
// them; it is made invertible by a spring at one well-chosen dof per motion ("pins"), whose
// K_s⁻¹ acts as a generalized inverse of K wherever the loads on the body balance along the free
// motions, Rᵀ(f − 𝔹ᵀλ) = 0 — the equality constraints Gλ = e (G = (𝔹R)ᵀ, e = Rᵀf) that the dual
// QP gets (qp/dual_qp_solver.hpp). Their multiplier μ is the body's rigid displacement: u = w − Rμ,
// w = K_s⁻¹(f − 𝔹ᵀλ). Normal contact holds the motions that move the body along the foundation's
// normal (a lift, a tilt about an axis in the plane); a motion in the plane (a slide, a turn about
// the normal) is held by friction alone, its equilibrium then a condition on the tangential
// multipliers (Σ friction forces = the tangential load). Frictionless contact holds it only when the
// loads along it balance (the pin then places the body, carrying no force). A mesh of several
// disconnected parts has each part's own motions (R's columns for a part vanish on the others), so
// each part that nothing prescribed holds is held by its own contact forces.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "base/errors.hpp"
#include "contact/foundation_frame.hpp"
#include "fem/assembly.hpp"
#include "fem/dof_map.hpp"
#include "mesh/mesh.hpp"

namespace contact3d {

struct ContactOperator;
struct Partition;
class DualQpSolver;
class TrescaStep;

// The free motions of one connected part of the mesh (the whole body when the mesh is one part):
// a mesh of several disconnected parts (no node shared) has each part's own rigid motions.
struct PartMotions {
  int part = 0;               // its number among the mesh's parts (fem::body_parts), from 0
  int parts = 1;              // how many parts the mesh has
  int tets = 0;               // its tetrahedra
  FreeRigidMotions free;      // the motions, about the part's centroid
  FreeRigidMotions named;     // the same in the user's frame (for messages)
  FreeRigidMotions in_plane;  // those of them that slide or turn in the foundation's plane, user frame
  // "part 2 of 3 (946 tetrahedra, centred at (…))" where the mesh has several parts, else "".
  std::string label() const;
};

struct ContactHeldMotions {
  std::vector<PartMotions> parts;         // the parts with free motions; their columns in `field` in this order
  Eigen::MatrixXd in_plane_combinations;  // k × (in-plane motions): the in-plane ones as combinations of the free
  Eigen::MatrixXd normal_combinations;    // k × (the others): those with a normal part (both block diagonal by part)
  Eigen::MatrixXd field;                  // n_free × k: the motions at the free dofs (R), each part's on its own dofs
  std::vector<int> pins;                  // k free dofs with a spring, where R's rows are best conditioned
  std::vector<double> pin_springs;        // the springs added to K's diagonal there (K_s = K + Σ s_p e_p e_pᵀ)
  double size = 1;                        // the largest extent of a part with free motions
  FoundationFrame user_frame;             // the user's axes, for naming a combination of the motions
  int count() const { return static_cast<int>(field.cols()); }
  int in_plane_count() const { return static_cast<int>(in_plane_combinations.cols()); }
  // "a translation along (0, 0, 1)" and so on, one per motion, joined by " and " (each part's after
  // its label, the parts joined by "; ").
  std::string describe() const;
  std::string describe_in_plane() const;  // the same for the in-plane motions ("" where none)
  // K_s w − (K_s − K) w: K w from a product by K_s.
  void remove_springs(const Eigen::VectorXd& w, Eigen::VectorXd& Ks_w) const;
};

// The free rigid motions of a body whose contact face lies on the plane z = 0 (the solve's frame),
// each part's own where the mesh has several: none (count() = 0) when the prescribed components
// hold every part. Throws InputError, naming the part and motion, when a motion is free and
// `has_contact` is false.
// Messages name the motions in `user_frame`'s global axes (the solve's frame is the plane's).
ContactHeldMotions contact_held_motions(const Mesh& mesh, const DofMap& dofs, bool has_contact,
                                        const FoundationFrame& user_frame = FoundationFrame());

// Throws InputError when a part with free motions has no free dof on Γc (`face_dofs`: the free dofs
// of the contact nodes): nothing could hold it.
void require_free_parts_on_contact_face(const ContactHeldMotions& held, const std::vector<int>& face_dofs);

// Adds the pins' springs (each equal to K's diagonal entry there) to K; records them in `held`.
void add_pin_springs(Eigen::SparseMatrix<double>& K, ContactHeldMotions& held);
// The same springs for a K assembled elsewhere (the distributed backend's ranks add them): K's
// diagonal at the pins from the elements, recorded in `held` only.
void add_pin_springs(const Mesh& mesh, const DofMap& dofs, const TetMaterials& materials, ContactHeldMotions& held);

// A refusal of a body held by contact alone whose cure is smaller cells: its contact zone spans too
// few of them to hold the loads' moments. With contact.cell_size = "auto" the scene is solved again
// with cells of 1.5h before the refusal is given (refine_refused_cells).
struct ContactZoneTooCoarse : InputError {
  using InputError::InputError;
};

// After the dual solve of a body held by contact alone: an InputError (a ContactZoneTooCoarse where
// smaller cells may cure it) when the contact forces could not balance the loads along the free
// motions — the loads pull the body off the foundation or tilt it about an edge of the contact face,
// push it along the plane harder than friction holds, or the body touches on too few cells to balance
// their moments — or balanced them only after a rigid displacement many times the body's size.
// `motions`: the rigid motions among the dual's equalities (held.field, or its combinations with a
// normal part where frictionless), `f` the loads on the free dofs; `coulomb`: the friction model, for the
// keys the refusal names.
void require_held(const ContactHeldMotions& held, const Eigen::MatrixXd& motions, const Eigen::VectorXd& f,
                  const ContactOperator& op, const Partition& partition, const DualQpSolver& qp,
                  const TrescaStep& tresca, bool coulomb);

// How hard the loads lean on friction along the in-plane motions (a slide, a turn about the normal):
// over their combinations r, the largest ratio of the work the friction forces do along r, Σ λ_t,i ·
// (𝔹_t r)_i (equal to the tangential loads' by equilibrium), to the most they could do along it,
// Σ c_i ‖(𝔹_t r)_i‖ with c_i the discs' radii — the minimum of a sum of norms under one linear
// constraint, solved by reweighted least squares. A share of 1 is friction at its limit: every pressed
// cell slides at its bound, all against r, and any further rigid slide along r solves the problem as
// well (the answer's place along r is one of many).
struct FrictionHold {
  double share = 0;       // in [0, 1]; 0 where no in-plane motion is free or nothing pushes along them
  std::string motion;     // the combination r that takes the largest share, named in the user's axes
  Eigen::VectorXd slide;  // that combination's motion at the free dofs (held.field · r; empty: none)
};
FrictionHold friction_hold(const ContactHeldMotions& held, const ContactOperator& op, const TrescaStep& tresca);

// The part of a rigid displacement at the free dofs along one motion (FrictionHold::slide): its
// least-squares multiple of it.
Eigen::VectorXd part_along(const Eigen::VectorXd& motion, const Eigen::VectorXd& rigid);

// A rigid displacement of the body held by contact alone more than this many times its size: the
// contact balanced the loads only by moving it along a motion it cannot hold (a linear model's
// rigid motion that large is no answer).
inline constexpr double kLargestRigidMotion = 10;

// Frictionless contact leaves the in-plane motions (slides, the turn about the normal) to the loads `f`
// (at the free dofs): an InputError where they do not balance along them. Before any factorization, so
// that `check` refuses what the solve would (it said ok to a free block pushed sideways, frictionless).
// `how_to_add_friction`: what the message tells to set (Scene::how_to_add_friction).
void require_in_plane_balance(const ContactHeldMotions& held, const Eigen::VectorXd& f,
                              const std::string& how_to_add_friction);

// Contact pushes only: where nothing prescribed holds a part's lift off the plane, an InputError when
// the loads `f` (at the free dofs) pull that part away from it (their resultant along the normal);
// `applied`: f without the loads of prescribed values, the scale of what counts as a pull. Before any
// factorization, after require_free_parts_on_contact_face, so that `check` refuses it as the solve does.
void require_loads_press_onto_plane(const ContactHeldMotions& held, const Eigen::VectorXd& f,
                                    const Eigen::VectorXd& applied);

// The share of FrictionHold at which friction has reached its limit (the QP meets its radii to about
// 1e-6): the slide along that motion is then not determined.
inline constexpr double kFrictionHoldReached = 1 - 1e-6;

}  // namespace contact3d
