#include "model/solution_checks.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "base/format.hpp"
#include "base/multiplier_layout.hpp"
#include "contact/partition.hpp"
#include "fem/assembly.hpp"
#include "mesh/mesh_checks.hpp"
#include "model/held_by_contact.hpp"
#include "model/solution_fields.hpp"

namespace contact3d {

// "H = 0.05" (the cell size asked for), or the range of a graded partition's rectangles.
std::string cell_sizes(const SolveResult& res) {
  return res.partition.graded ? describe_cell_sizes(res.partition) : "H = " + number(res.cell_size, 3);
}

namespace {

// Tresca's bound F·g does not depend on the contact pressure, so (the paper's model) friction
// acts also where the body has lifted off (λ_n = 0). Said in a warning with the area, since a
// user may expect Coulomb's behaviour there.
void flag_friction_where_separated(const Scene& scene, SolveResult& res) {
  const int r = res.n_cells;
  if (scene.coulomb() || !has_friction(r, res.lambda)) return;
  const MultiplierLayout at{r, true};
  const std::vector<int> status = cell_status(r, res.lambda, res.radius);
  const double t_max = res.lambda.tail(2 * r).cwiseAbs().maxCoeff();
  double area = 0;
  int cells = 0;
  for (int i = 0; i < r; ++i)
    if (status[i] == kSeparated && std::hypot(res.lambda[at.t1(i)], res.lambda[at.t2(i)]) > 1e-3 * t_max) {
      area += res.partition.cells[i].area;
      ++cells;
    }
  res.friction_where_separated_area = area;
  if (cells > 0)
    res.notes.push_back("Tresca friction acts on " + std::to_string(cells) + " cells (area " + number(area, 4) + " " +
                        unit_labels(scene.output.units).length +
                        "²) where the body has lifted off (λ_n = 0): the bound F·g does not depend on the contact "
                        "pressure (the paper's model); friction.model = \"coulomb\" ties it to the pressure");
}

// Every cell's λ_n ≤ 0: nothing presses on the foundation (false without cells).
bool no_cell_presses(const SolveResult& res) {
  const Eigen::Index r = static_cast<Eigen::Index>(res.partition.cells.size());
  return r > 0 && res.lambda.size() >= r && res.lambda.head(r).maxCoeff() <= 0;
}

bool motionless(const SolveResult& res) { return res.u.size() == 0 || res.u.cwiseAbs().maxCoeff() == 0; }

// No cell presses on the foundation (every λ_n ≤ 0), said with what the run shows of why (a body that
// does not move at all: flag_motionless):
//  - Γc started above the plane and the loads did not bring it down: a warning naming the gap. The
//    usual cause is the plane's place, not the loads: a mesh in CAD coordinates whose sole lies at
//    z = 1 m solved with "converged" and zero contact force, with nothing said (the paper's brick
//    lifted 1 m);
//  - the loads lift a face that rested on the plane off all over, or leave it touching without
//    pressing on it: a note.
void flag_no_contact(const Mesh& mesh, SolveResult& res) {
  if (!no_cell_presses(res) || res.face.nodes.empty() || motionless(res)) return;
  int lowest = res.face.nodes.front(), closest = lowest;
  auto height_after = [&](int v) { return res.face.gap[v] + res.u[3 * v + 2]; };  // the mesh is in the plane's frame
  for (const int v : res.face.nodes) {  // Clamped nodes are not among them (ContactFace::nodes).
    if (res.face.gap[v] < res.face.gap[lowest]) lowest = v;
    if (height_after(v) < height_after(closest)) closest = v;
  }
  auto tag = [&](int v) { return std::to_string(mesh.node_tags[static_cast<std::size_t>(v)]); };
  const std::string after = "of its nodes, the one closest to it ends " + number(height_after(closest), 3) +
                            " above it (node " + tag(closest) + ")";
  if (res.face.gap[lowest] > 0)
    res.warnings.push_back("no cell touches the foundation: the contact face starts " +
                           number(res.face.gap[lowest], 3) + " above the foundation plane at its lowest node (node " +
                           tag(lowest) + ") and the loads do not close that gap: " + after +
                           "; if the body should rest on the foundation, put the plane there (contact.plane_point, "
                           "plane_normal) or move the mesh, and check the mesh's units");
  else if (height_after(closest) > 0)
    res.notes.push_back(
        "no cell is in contact: the loads and prescribed displacements lift the whole contact face off "
        "the foundation; " +
        after);
  else
    res.notes.push_back("no cell presses on the foundation: the contact face touches it (node " + tag(closest) +
                        ") but the loads press nowhere on it");
}

// Non-penetration holds as averages over the cells R_i (the paper's mixed method), so single nodes
// inside a cell may penetrate; on a body resolved against its cells by a small fraction of its
// displacement (the paper's brick at n = 16: 0.7%, the bodies of results/bodies: at most 3.3%). When the body deforms
// inside a cell — a body about as thin as a cell, one element layer under cells of 2h, or a contact zone only a few
// cells wide — the penetration becomes a large part of the displacement and the solution near Γc is not resolved,
// whatever the residuals say (the thin slab against FreeFEM, results/crosscheck/slab_series.md: 77% penetration ↔ 91%
// difference at h = t, 11% ↔ 11% with cells of 1.5h).
constexpr double kUnresolvedPenetration = 0.1;  // of the body's largest displacement

// max over nodes of ‖u_node‖ for u laid out (x, y, z) by node.
double largest_nodal_displacement(const Eigen::VectorXd& u) {
  double largest = 0;
  for (Eigen::Index p = 0; p + 2 < u.size(); p += 3) largest = std::max(largest, u.segment<3>(p).norm());
  return largest;
}

}  // namespace

bool unresolved(const SolveResult& res) { return res.penetration_ratio > kUnresolvedPenetration; }

// The largest nodal displacement of `u_free` expanded to the nodes, less the rigid motion the
// prescribed values impose (prescribed_rigid_motion) and less its least-squares fit by the rigid
// motions `held` (n_free × k, none: nothing removed). A body may approach the foundation rigidly by far
// more than it deforms — held by contact alone and hovering over its gaps, or a punch pushed down
// across a gap by a prescribed u_z = −δ: its penetration is measured against the deformation, not the
// approach.
double largest_deformation(const Mesh& mesh, const DofMap& dofs, const Eigen::VectorXd& u_free,
                           const Eigen::MatrixXd& held) {
  Eigen::VectorXd u = expand_to_nodes(dofs, u_free) - prescribed_rigid_motion(mesh, dofs);
  if (held.cols()) {
    Eigen::VectorXd free_part(dofs.n_free);
    for (std::size_t i = 0; i < dofs.free_index.size(); ++i)
      if (const int d = dofs.free_index[i]; d >= 0) free_part[d] = u[static_cast<Eigen::Index>(i)];
    // Normal equations: R's columns are rigid motions in coordinates scaled by the part's size, so RᵀR
    // is well conditioned, and its product is blocked (a mesh of 24 parts: 144 columns).
    free_part = held * (held.transpose() * held).ldlt().solve(held.transpose() * free_part);
    for (std::size_t i = 0; i < dofs.free_index.size(); ++i)
      if (const int d = dofs.free_index[i]; d >= 0) u[static_cast<Eigen::Index>(i)] -= free_part[d];
  }
  return largest_nodal_displacement(u);
}

// A penetration against the body's largest displacement, to go before "the … displacement": "3.1% of",
// "150% of" (whole percents from 10%: two significant digits printed 150% as "1.5e+02%"), or "3.1e+05
// times" past 1000%.
std::string share_of_displacement(double ratio) {
  const double percent = 100 * ratio;
  if (!(ratio <= 10)) return number(ratio, 2) + " times";  // NaN too: lround would not print it
  return (percent < 10 ? number(percent, 2) : std::to_string(std::lround(percent))) + "% of";
}

namespace {

// No cell presses (every λ_n ≤ 0) while nodes penetrate: the approach closed no cell's mean gap.
bool penetrates_without_pressure(const SolveResult& res) { return res.wn_plus_inf > 0 && no_cell_presses(res); }

// Non-penetration is enforced on boundary.contact only. A part of the body that rests on the plane
// but is in no contact group sinks through it with nothing said: a 3 x 1 x 1 brick whose contact
// groups were its sole's two end patches converged with the sole's middle 0.78 mm below the plane,
// and max_penetration (Γc's nodes only) read 7.8e-5. Said in a warning where a node off Γc ends
// below the plane by more than 1% of the largest displacement, naming the deepest.
constexpr double kPenetrationOffContact = 0.01;  // of the largest nodal displacement
void flag_penetration_outside_contact(const Mesh& mesh, SolveResult& res) {
  const double u_max = largest_nodal_displacement(res.u);
  if (!(u_max > 0) || res.face.contact_index.size() != mesh.nodes.size()) return;
  std::size_t below = 0, deepest = 0;
  double depth = 0;  // the mesh is in the plane's frame: a node's height is its z
  const std::vector<char> in_body = nodes_of_tets(mesh);
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v) {
    if (res.face.contact_index[v] >= 0 || !in_body[v]) continue;
    const double height = mesh.nodes[v].z() + res.u[static_cast<Eigen::Index>(3 * v + 2)];
    if (height >= -kPenetrationOffContact * u_max) continue;
    ++below;
    if (-height > depth) depth = -height, deepest = v;
  }
  if (below == 0) return;
  res.warnings.push_back(std::to_string(below) +
                         " node(s) outside the contact groups end below the foundation plane, "
                         "the deepest (node " +
                         std::to_string(mesh.node_tags[deepest]) + ") by " + number(depth, 3) + " (" +
                         share_of_displacement(depth / u_max) +
                         " the largest displacement): non-penetration is enforced on boundary.contact only, so that "
                         "part of the body passes through the foundation; if it rests on the foundation, add its faces "
                         "to the contact groups");
}

}  // namespace

// The cells that carry a normal force: those with more than 1e-3 of the largest cell force (λ_n · area).
// A balance found by leaning on cells that barely touch does not count them.
std::vector<int> cells_pressed(const Eigen::VectorXd& lambda, const Partition& partition) {
  const int r = static_cast<int>(partition.cells.size());
  std::vector<int> pressed;
  if (lambda.size() < r) return pressed;
  Eigen::VectorXd force(r);
  for (int i = 0; i < r; ++i) force[i] = std::max(lambda[i], 0.0) * partition.cells[static_cast<std::size_t>(i)].area;
  const double largest = r ? force.maxCoeff() : 0.0;
  if (!(largest > 0)) return pressed;
  for (int i = 0; i < r; ++i)
    if (force[i] > 1e-3 * largest) pressed.push_back(i);
  return pressed;
}

// The covariance of the centres of `cells` (all cells where empty): its smaller eigenvalue says how
// far they spread across their narrowest direction.
Eigen::Matrix2d centroid_spread(const Partition& partition, std::vector<int> cells) {
  if (cells.empty())
    for (int i = 0; i < static_cast<int>(partition.cells.size()); ++i) cells.push_back(i);
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const int i : cells) mean += partition.cells[i].centroid / static_cast<double>(cells.size());
  Eigen::Matrix2d spread = Eigen::Matrix2d::Zero();
  for (const int i : cells) {
    const Eigen::Vector2d d = partition.cells[i].centroid - mean;
    spread += d * d.transpose() / static_cast<double>(cells.size());
  }
  return spread;
}

namespace {

// A contact zone about two cells across or less, on a face several times wider: the zone's size and
// its peak pressure are resolved only to a cell (a Hertz strip 0.77 mm wide on cells of 0.47 mm came out
// one row of cells, its area 40% short and its peak pressure 41% high, while the penetration stayed
// within bounds and the normal force was right). The width is measured across the pressed cells'
// centres (cells carrying over 1e-3 of the largest cell force), in cells of their mean size: a row of
// k cells has centres spread by side·√((k² − 1)/12). Measured over the whole zone, and around each
// pressed cell within kNarrowZoneWindow cells (the median of those): a strip that curves (a ring's line
// contact, one cell wide along a quarter circle) spreads in both directions as a whole, but not locally.
constexpr double kNarrowZoneCells = 2.2;
constexpr double kNarrowZoneWindow = 4;         // cells: a full window is ≈ 7 cells across
constexpr std::size_t kNarrowZoneLocal = 4000;  // pressed cells beyond which only the whole zone is measured

struct ZoneWidth {
  double zone = INFINITY;  // cells across the pressed cells, along their narrowest direction
  double face = 0;         // cells across the face's cells along that direction
  bool narrow() const { return zone <= kNarrowZoneCells && face >= 2 * zone + 1; }
};

// The widths of `pressed` and of `face` (cell indices) along the pressed cells' narrowest direction.
ZoneWidth zone_width(const Partition& partition, const std::vector<int>& pressed, const std::vector<int>& face,
                     double side) {
  const auto cells_across = [side](double variance) {
    return std::sqrt(12 * std::max(variance, 0.0) / (side * side) + 1);
  };
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(centroid_spread(partition, pressed));
  const Eigen::Vector2d narrow = eig.eigenvectors().col(0);
  return {cells_across(eig.eigenvalues()[0]), cells_across(narrow.dot(centroid_spread(partition, face) * narrow))};
}

double median(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// The median over the pressed cells of the zone's width within a window around each.
ZoneWidth local_zone_width(const Partition& partition, const std::vector<int>& pressed, double side) {
  const double reach = kNarrowZoneWindow * side;
  const auto near = [&](const std::vector<int>& cells, const Eigen::Vector2d& centre) {
    std::vector<int> within;
    for (const int j : cells)
      if ((partition.cells[j].centroid - centre).norm() <= reach) within.push_back(j);
    return within;
  };
  std::vector<int> all(partition.cells.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  std::vector<double> zones, faces;
  for (const int i : pressed) {
    const Eigen::Vector2d& centre = partition.cells[i].centroid;
    const ZoneWidth w = zone_width(partition, near(pressed, centre), near(all, centre), side);
    zones.push_back(w.zone), faces.push_back(w.face);
  }
  return {median(zones), median(faces)};
}

void flag_narrow_contact_zone(SolveResult& res) {
  if (res.n_cells < 4) return;
  const std::vector<int> pressed = cells_pressed(res.lambda, res.partition);
  if (pressed.empty()) return;
  double pressed_area = 0;
  for (const int i : pressed) pressed_area += res.partition.cells[i].area;
  const double side = std::sqrt(pressed_area / static_cast<double>(pressed.size()));
  if (!(side > 0)) return;
  ZoneWidth width = zone_width(res.partition, pressed, {}, side);
  if (!width.narrow() && pressed.size() <= kNarrowZoneLocal) width = local_zone_width(res.partition, pressed, side);
  if (!width.narrow()) return;
  res.warnings.push_back("the contact zone is about " + number(width.zone, 2) + " cell(s) across at its narrowest (" +
                         std::to_string(pressed.size()) + " pressed cells of about " + number(side, 3) +
                         "): its size and its peak pressure are resolved only to a cell, and the pressure there is "
                         "a cell's average, and the displacement near it may be off by tens of percent (a foot "
                         "tipped onto its edge: u on Γc 31% from a nodal contact's on the same mesh), and so may the "
                         "contact force where an approach is prescribed (a V-shaped sole pushed 10 µm: 59% below a "
                         "nodal contact's, 45% on a mesh twice as fine); refine the mesh "
                         "where it touches until the zone spans several cells "
                         "(a mesh graded towards the contact gives cells that follow its size)");
}

// `u_max`: largest_deformation; `rigid_removed`: it is less a rigid motion (held by contact alone, or
// imposed by prescribed values).
// The penetration against the displacement of Γc itself, where the body's deformation (the warning's
// measure) hides it: a sole that sticks under Coulomb friction moves by micrometres while the body above
// deforms by far more, and its edge nodes penetrated by 70–80% of the sole's largest displacement (u on Γc
// 0.9 from FreeFEM's nodal answer, forces within 0.5%), with nothing said. A note: the body's answer and
// the forces are resolved; the face's own displacement (slip, gap) is not.
constexpr double kFacePenetrationNote = 0.3;
void note_penetration_against_face_motion(SolveResult& res) {
  double face_u = 0;
  for (const int v : res.face.nodes) face_u = std::max(face_u, res.u.segment<3>(3 * v).norm());
  if (!(face_u > 0) || res.wn_plus_inf <= kFacePenetrationNote * face_u) return;
  res.notes.push_back("the largest nodal penetration (" + number(res.wn_plus_inf, 3) + ") is " +
                      share_of_displacement(res.wn_plus_inf / face_u) + " the largest displacement on Γc (" +
                      number(face_u, 3) +
                      "), though small against the body's: the contact face barely moves (it sticks or is pressed "
                      "flat), so its own displacement — slip, gap — is resolved only to the cells' averages, while "
                      "the forces and the body's displacement are; refine the mesh near Γc for the face's values");
}

// The largest gap d − w_n left open at a contact node whose hat function lies wholly in pressed cells:
// (5.4) holds w_n − d ≤ 0 as each cell's average, so beside the nodes that penetrate stand nodes that
// stay off the plane under a cell that carries pressure (a soft layer's corner 3.9 µm up, 21% of its
// largest displacement, listed in contact, while its penetration stayed at 9.7%: u on Γc 32% from a
// nodal contact's, the normal force 0.7%, nothing said). A node whose normal component is prescribed is
// left out: a finer mesh would not move it.
double open_gap_under_pressed_cells(const SolveResult& res) {
  const std::vector<int> pressed = cells_pressed(res.lambda, res.partition);
  if (pressed.empty()) return 0;
  std::vector<double> total(res.face.gap.size(), 0.0), in_pressed(res.face.gap.size(), 0.0);
  const auto rows = cell_node_weights(res.face, res.partition);
  std::vector<char> is_pressed(rows.size(), 0);
  for (const int i : pressed) is_pressed[static_cast<std::size_t>(i)] = 1;
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (const auto& [node, weight] : rows[i]) {
      total[static_cast<std::size_t>(node)] += weight;
      if (is_pressed[i]) in_pressed[static_cast<std::size_t>(node)] += weight;
    }
  double largest = 0;
  for (const int v : res.face.nodes) {
    const auto k = static_cast<std::size_t>(v);
    if (!(total[k] > 0) || in_pressed[k] < (1 - 1e-9) * total[k] || res.dofs.dof(v, 2) < 0) continue;
    largest = std::max(largest, res.face.gap[k] + res.u[3 * v + 2]);  // d − w_n, w_n = −u_z
  }
  return largest;
}

// A material this near incompressible, pressed flat, bulges towards the face's edges, and its P1 tetrahedra lock:
// a helper's rubber layer under steel penetrated by 7.4% of its displacement at ν = 0.3, 18.5% at 0.45 and
// 0.48, and the penetration warning named neither.
constexpr double kBulgingPoisson = 0.45;
double largest_poisson(const Scene& scene) {
  double largest = scene.material.poisson;
  for (const auto& region : scene.regions) largest = std::max(largest, region.material.poisson);
  return largest;
}

void flag_unresolved_contact(const Scene& scene, double u_max, bool rigid_removed, SolveResult& res) {
  res.penetration_ratio = u_max > 0 ? res.wn_plus_inf / u_max : 0.0;
  const double open_gap = open_gap_under_pressed_cells(res);
  res.open_gap_ratio = u_max > 0 ? open_gap / u_max : 0.0;
  if (!unresolved(res) && res.open_gap_ratio > kUnresolvedPenetration) {
    res.warnings.push_back(
        "a contact node under cells that carry pressure stands " + number(open_gap, 3) + " off the foundation, " +
        share_of_displacement(res.open_gap_ratio) + " the body's largest displacement" +
        (rigid_removed ? std::string(" less its rigid motion") : std::string()) +
        ": non-penetration holds as averages over cells of " + cell_sizes(res) +
        ", so where the body deforms inside a cell some of its nodes stay off the plane while others penetrate "
        "(the largest penetration: " +
        share_of_displacement(res.penetration_ratio) +
        " it), and the displacement near Γc is not resolved (a soft layer: u on Γc 32% from a nodal contact's, the "
        "normal force 0.7%); refine the mesh (h), most where it stands off (the cells of a graded mesh follow its "
        "element size)");
  }
  if (!unresolved(res)) {
    note_penetration_against_face_motion(res);
    return;
  }
  if (penetrates_without_pressure(res)) {
    // A cone on its tip pushed down: the tip's cell averages a gap of millimetres over its area, which
    // the approach does not close, so the tip passes through the foundation with no force at all.
    res.warnings.push_back(
        "nodes penetrate the foundation by up to " + number(res.wn_plus_inf, 3) +
        " while no cell carries a contact force: non-penetration holds as averages of w_n − d over cells of " +
        cell_sizes(res) +
        ", and where the body touches on a zone much smaller than a cell (a tip, a point, a steep curved face) "
        "the approach closes the part of the face that touches but not the cell's mean gap, so the body passes "
        "through the foundation there unresisted; refine the mesh where it touches until its cells are about as "
        "small as the zone that touches (a mesh graded towards the contact zone gives cells that follow its "
        "size), or check the prescribed approach");
    return;
  }
  const double poisson = largest_poisson(scene);
  res.warnings.push_back("the largest nodal penetration (" + number(res.wn_plus_inf, 3) + ") is " +
                         share_of_displacement(res.penetration_ratio) + " the body's largest displacement" +
                         (rigid_removed ? std::string(" less its rigid motion") : std::string()) +
                         ": non-penetration holds as averages over cells of " + cell_sizes(res) +
                         " and the body deforms inside a cell (a body about as thin as a cell, a contact zone a "
                         "few cells wide, or the pressure peak at a flat sole's edges and corners" +
                         (poisson >= kBulgingPoisson
                              ? ", made worse by a nearly incompressible material (ν = " + number(poisson, 3) +
                                    ": pressed flat it bulges towards the edges, and P1 tetrahedra lock)"
                              : std::string()) +
                         "), so the "
                         "displacement near Γc is not resolved; refine the mesh (h), most where it penetrates (the "
                         "cells of a graded mesh follow its element size)" +
                         (scene.cell_size_auto ? std::string(" (contact.cell_size = \"auto\" tried cells of 1.5h: "
                                                             "see its note)")
                          : scene.cell_size_relative && scene.cell_size <= kRefinedCellSize
                              ? std::string(" (cells smaller than 1.5h make Q ill-conditioned)")
                              : std::string(" or use a smaller contact.cell_size, e.g. \"1.5h\" (watch cond(Q))")));
}

}  // namespace

// A body that does not move at all, with or without a contact face (a scene of a clamp alone solved
// with nothing said): a warning that nothing loads it, or, where loads were applied, that they act only
// on nodes whose displacement is prescribed (a traction on the clamped group was told "every traction
// ... is zero").
void flag_motionless(const Scene& scene, SolveResult& res) {
  if (!motionless(res)) return;
  const char* const contact_forces = res.face.nodes.empty() ? "" : " and the contact forces";
  if (res.forces.applied.norm() > 0) {
    res.warnings.push_back("the body does not move: its loads (resultant " + number(res.forces.applied.norm(), 4) +
                           " " + unit_labels(scene.output.units).force +
                           ") act only on nodes whose displacement is prescribed, and the supports take them (see "
                           "the reactions); put the loads on the faces they act on");
    return;
  }
  res.warnings.push_back(std::string("nothing loads the body: every traction, pressure, body force and prescribed "
                                     "displacement of the scene is zero, so are the displacement") +
                         contact_forces);
}

// contact3d solves linear elasticity (small strains and rotations, the contact condition on the
// undeformed face), which describes a body strained by a few percent at most. Far beyond that the
// answer is the linear model's, not the body's, and the usual cause is a scene in mixed units: young in
// MPa with lengths in metres strains a steel block a million times too much, and the only other warning
// was about penetration, which asked for a finer mesh. Said before any other warning. The other slip,
// loads in MPa with young in Pa, strains it a million times too little: said in a note below kTinyStrain
// (where no load acts, the note says instead that the prescribed values move the body rigidly).
constexpr double kLargeStrain = 0.1;
constexpr double kTinyStrain = 1e-9;  // a steel part's own weight strains a 1 cm part by 4e-9
// A peak beyond kLargeStrain where 99% of the volume stays under half of it is local (a nylon block with
// a stepped sole, pushed 0.8 mm down over 40 mm: 11% at the step's re-entrant corner, 2.3% elsewhere, which
// the warning blamed on the units); a scene in mixed units strains the whole body far beyond it.
constexpr double kLocalPeakBulk = 0.5 * kLargeStrain;
// Up to this peak, a body strained over much of its volume is more likely a soft body really pressed that
// far (a rubber layer under a 5% compression reached 11% at its edge, and the warning blamed the units)
// than a scene in mixed units, which strains it by orders of magnitude (young in MPa with lengths in m: a
// million times): the answer is said to be a rough approximation, not wrong.
constexpr double kRoughlyLinearStrain = 0.25;
void flag_large_strain(const Mesh& mesh, SolveResult& res) {
  const StrainPeak peak = largest_strain(mesh, res.u);
  res.largest_strain = peak.value;
  if (peak.value > 0 && peak.value < kTinyStrain && res.forces.applied.norm() == 0) {
    res.notes.push_back("the largest strain is " + number(peak.value, 3) +
                        ": no load acts and the prescribed displacements move the body rigidly, so nothing strains "
                        "it");
    return;
  }
  if (peak.value > 0 && peak.value < kTinyStrain) {
    res.notes.push_back("the largest strain is " + number(peak.value, 3) +
                        ", far below a loaded part's usual 1e-5 … 1e-3: check that loads and moduli are in one "
                        "system of units (loads in MPa with young in Pa make every displacement a million times too "
                        "small, and a gap or a slip-dependent coefficient then acts on the wrong scale)");
    return;
  }
  if (!(peak.value > kLargeStrain)) return;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const int v : mesh.tets[peak.tet]) centre += mesh.nodes[static_cast<std::size_t>(v)] / 4;
  const std::string where = "the largest strain is " + number(peak.value, 3) + " (" + number(100 * peak.value, 3) +
                            "%) in tetrahedron " + std::to_string(peak.tet + 1) + ", centred at (" +
                            number(centre.x(), 4) + ", " + number(centre.y(), 4) + ", " + number(centre.z(), 4) +
                            "): contact3d solves linear elasticity (small strains and rotations, contact on the "
                            "undeformed face), which describes strains of a few percent at most";
  const std::string units =
      "check that the scene is in one consistent system of units (young in Pa with lengths in m "
      "and forces in N, or in MPa with mm)";
  std::string why;
  if (peak.bulk < kLocalPeakBulk)
    why = ", so this is not the body's answer there; 99% of the body's volume is strained less than " +
          number(100 * peak.bulk, 2) +
          "%, so the peak is local (a re-entrant corner, a sole's edge or corner, a point load or support, where the "
          "linear model's strain is singular and grows as the mesh is refined) and the rest of the answer is not "
          "concerned; if there is no such place, " +
          units;
  else if (peak.value <= kRoughlyLinearStrain)
    why = ", so the answer is only a rough approximation: 1% of the body's volume is strained more than " +
          number(100 * peak.bulk, 2) +
          "%, as a soft body under a large imposed compression or load is (a rubber layer pressed by 5%), and the "
          "linear model's error grows with the strain; if the scene should strain it far less, " +
          units + ", and the size of its loads and prescribed displacements";
  else
    why = ", so this is not the body's answer; " + units + ", and the size of its loads and prescribed displacements";
  res.warnings.insert(res.warnings.begin(), where + why);
}

namespace {

// A coefficient with a jump is not Lipschitz, so the existence-and-uniqueness argument behind (5.7)
// does not hold and the discrete problem may have several solutions: on the thin slab of
// results/robustness.md (jump law) a start from a large slip instead of φ⁰ = 0 converged to a
// solution 28% away in u. Said in a note, with which solution this is.
void flag_possible_nonuniqueness(const Scene& scene, SolveResult& res) {
  if (const std::optional<double> t = scene.law.jump_at(); t && scene.needs_fixed_point())
    res.notes.push_back("friction.points jumps at t = " + number(*t, 3) +
                        ": with a discontinuous coefficient the problem may have more than one solution (the "
                        "paper's uniqueness needs a Lipschitz F with a small modulus); this is the one the "
                        "successive approximations (5.7) reach from φ⁰ = 0, the sticking start");
}

// The recovered displacement out of equilibrium, ‖K w − f + 𝔹ᵀλ‖ above this share of the forces:
// the KKT residuals of a sound solve are rounding (1e-12 on the brick, 1e-8 on bodies held by contact
// alone), so this is no answer whatever the QP's own residual says.
constexpr double kInaccurateEquilibrium = 1e-4;

void flag_inaccurate_equilibrium(SolveResult& res) {
  if (!(res.kkt.equilibrium > kInaccurateEquilibrium)) return;
  res.warnings.push_back("the displacement satisfies the equilibrium K u = f − 𝔹ᵀλ only to " +
                         number(res.kkt.equilibrium, 2) +
                         " of the forces (summary.json kkt.equilibrium): the answer is inaccurate, whatever the dual "
                         "solve's own residual says; " +
                         (res.friction_limit_slide > kLargestRigidMotion
                              ? std::string("friction is at its limit (see that warning), and the slide it leaves "
                                            "undetermined is so large that the body's own deformation keeps only a "
                                            "few digits in the displacement")
                              : std::string("check that the supports hold every rigid motion the contact cannot "
                                            "(boundary.clamped, boundary.displacement)")));
}

}  // namespace

// Nodes below the plane by at most kPenetrationRounding of the body's diagonal are on it, as for the
// initial penetration (mesh_checks.hpp): an unloaded body resting on z = 0 gets no note.
void note_body_below_plane_without_contact(const Mesh& mesh, SolveResult& res) {
  const double u_max = largest_nodal_displacement(res.u);
  const std::vector<char> in_body = nodes_of_tets(mesh);
  const double tolerance = std::max(kPenetrationOffContact * u_max, kPenetrationRounding * body_diagonal(mesh));
  std::size_t below = 0, deepest = 0;
  bool starts_above = true;  // no node of the body starts below the plane
  double depth = 0;          // the mesh is in the plane's frame: a node's height is its z
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v) {
    if (!in_body[v]) continue;
    starts_above = starts_above && mesh.nodes[v].z() >= -tolerance;
    const double lowest = std::min(mesh.nodes[v].z(), mesh.nodes[v].z() + res.u[static_cast<Eigen::Index>(3 * v + 2)]);
    if (lowest >= -tolerance) continue;
    ++below;
    if (-lowest > depth) depth = -lowest, deepest = v;
  }
  if (below == 0) return;
  const std::string text =
      "the scene has no contact group (boundary.contact), so the foundation plane holds nothing: " +
      std::to_string(below) + " node(s) " + (starts_above ? "end" : "start or end") + " below it, the deepest (node " +
      std::to_string(mesh.node_tags[deepest]) + ") by " + number(depth, 3) +
      "; if the body rests on the foundation, name its contact faces in boundary.contact";
  // A body that starts on or above the plane and is pushed through it most likely rests on it: a
  // forgotten contact group (a helper's strip clamped at one end ended 0.436 m below with a note only).
  if (starts_above)
    res.warnings.push_back(text);
  else
    res.notes.push_back(text);
}

// After recovery (u, λ, the KKT residuals, w_n⁺ and the forces known): the warnings and notes on the
// answer, in the order the run prints them (a large strain's warning goes first).
void check_answer(const Scene& scene, const Mesh& mesh, double u_max, bool rigid_removed, SolveResult& res) {
  flag_inaccurate_equilibrium(res);
  flag_friction_where_separated(scene, res);
  flag_motionless(scene, res);
  flag_no_contact(mesh, res);
  flag_penetration_outside_contact(mesh, res);
  flag_large_strain(mesh, res);
  flag_unresolved_contact(scene, u_max, rigid_removed, res);
  flag_narrow_contact_zone(res);
  flag_possible_nonuniqueness(scene, res);
}

}  // namespace contact3d
