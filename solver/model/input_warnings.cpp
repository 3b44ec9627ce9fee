#include "model/input_warnings.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <utility>

#include <Eigen/Core>

#include "base/format.hpp"
#include "contact/face_thickness.hpp"
#include "mesh/mesh_checks.hpp"

namespace contact3d {
namespace {

// Linear tetrahedra lock volumetrically as ν approaches 1/2 (no mixed u–p form here): the
// displacement comes out too small on any but very fine meshes. Said once, for the largest ν in use.
constexpr double kNearlyIncompressible = 0.49;  // bulk / shear modulus ≈ 50
void warn_if_nearly_incompressible(const Mesh& mesh, const TetMaterials& materials, SolveResult& res) {
  double largest = 0;
  std::size_t count = 0;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const double nu = materials[e].poisson;
    largest = std::max(largest, nu);
    if (nu >= kNearlyIncompressible) ++count;
  }
  if (count == 0) return;
  const double bulk_over_shear = 2.0 * (1.0 + largest) / (3.0 * (1.0 - 2.0 * largest));
  res.warnings.push_back(
      "nearly incompressible material: ν = " + number(largest) + " on " + std::to_string(count) + " of " +
      std::to_string(mesh.tets.size()) + " tetrahedra (bulk / shear modulus " + number(bulk_over_shear, 3) +
      "); linear tetrahedra (P1) lock as ν approaches 1/2, so the displacement comes out too small unless the mesh "
      "is very fine (contact3d has no mixed u–p formulation): check that the answer changes little when h is halved");
}

// A Young's modulus above any solid's (diamond's is about 1.2e12 Pa) or below the softest gels' (about
// 1 kPa) is a unit slip: young in Pa where output.units says MPa (a mm mesh) makes every displacement a
// million times too small, and a gap or a slip-dependent coefficient then acts on the wrong scale, with
// nothing else to say so (the helper's mm brick: largest strain 1.8e-10); young = 210 meant in GPa makes
// it a billion times too large, and a body held by contact alone was refused for a rigid displacement
// thousands of times its size, blaming the contact cells.
constexpr double kStiffestSolidPa = 2e12, kSoftestSolidPa = 1e3;
void warn_if_beyond_any_solid(const Scene& scene, const Mesh& mesh, const TetMaterials& materials, SolveResult& res) {
  double stiffest = 0, softest = INFINITY;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    stiffest = std::max(stiffest, materials[e].young);
    softest = std::min(softest, materials[e].young);
  }
  const double pascal = pascal_per_stress_unit(scene.output.units);
  const UnitLabels units = unit_labels(scene.output.units);
  const std::string check = std::string(": check that the moduli are in ") + units.stress + ", as output.units = \"" +
                            name_of(scene.output.units, kUnitSystemNames) + "\" states; a modulus given in a ";
  if (stiffest * pascal > kStiffestSolidPa)
    res.warnings.push_back("young = " + number(stiffest, 4) + " " + units.stress +
                           " is stiffer than any solid (diamond's is about " + number(1.2e12 / pascal, 2) + " " +
                           units.stress + ")" + check +
                           "smaller unit makes every displacement as many times too small");
  if (softest * pascal < kSoftestSolidPa)
    res.warnings.push_back("young = " + number(softest, 4) + " " + units.stress +
                           " is softer than any solid but the softest gels (about " + number(1e3 / pascal, 2) + " " +
                           units.stress + ")" + check + "larger unit (GPa instead of " + units.stress +
                           ") makes every displacement as many times too large");
}

// Loads whose stress is as large as the stiffest Young's modulus or larger strain the body by 100% or
// more, far beyond the linear elasticity solved here; the usual cause is a scene in mixed units (young =
// 210000 meant in MPa with tractions in Pa, 48 times the modulus: a body held by contact alone was
// refused for a rigid displacement 37 times its size, blaming its contact cells, and `check` said ok).
// Not lower: a confined rubber cube (E = 1 MPa, ν = 0.49) under 0.2 MPa strains 1.2%, and a level of a
// tenth warned it. The stress: the largest traction or pressure at a node of a loaded triangle (value
// and gradient), or the body's own weight over its height along the body force.
constexpr double kLoadOverModulus = 1;
void warn_if_loads_beyond_linear_strain(const Scene& scene, const Mesh& mesh, const TetMaterials& materials,
                                        SolveResult& res) {
  double stiffest = 0;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) stiffest = std::max(stiffest, materials[e].young);
  if (!(stiffest > 0)) return;
  double traction = 0;
  for (const Traction& tr : scene.tractions) {
    if (!mesh.find_group(tr.group, 2)) continue;  // missing or not a surface: the checks that name it say so
    for (const int t : mesh.triangles_of_group(tr.group))
      for (const int v : mesh.triangles[static_cast<std::size_t>(t)]) {
        const Eigen::Vector3d& x = mesh.nodes[static_cast<std::size_t>(v)];
        traction = std::max(traction,
                            (tr.value + tr.gradient * x).norm() + std::abs(tr.pressure + tr.pressure_gradient.dot(x)));
      }
  }
  double weight = 0;
  Eigen::Vector3d heaviest = scene.body_force;  // of [material] and the regions'
  for (const auto& region : scene.regions)
    if (region.body_force && region.body_force->norm() > heaviest.norm()) heaviest = *region.body_force;
  if (heaviest.norm() > 0 && !mesh.tets.empty()) {
    const Eigen::Vector3d along = heaviest.normalized();
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& tet : mesh.tets)
      for (const int v : tet) {
        lo = std::min(lo, along.dot(mesh.nodes[static_cast<std::size_t>(v)]));
        hi = std::max(hi, along.dot(mesh.nodes[static_cast<std::size_t>(v)]));
      }
    weight = heaviest.norm() * (hi - lo);
  }
  const double stress = std::max(traction, weight);
  if (!(stress >= kLoadOverModulus * stiffest)) return;
  const UnitLabels units = unit_labels(scene.output.units);
  res.warnings.push_back(
      "the loads reach a stress of " + number(stress, 3) + " " + units.stress +
      (traction >= weight ? " (the largest traction or pressure)" : " (the body's own weight over its height)") + ", " +
      number(stress / stiffest, 3) + " times the stiffest material's young = " + number(stiffest, 4) + " " +
      units.stress + ": they would strain the body by about " + number(100 * stress / stiffest, 3) +
      "%, far beyond the small strains of the linear elasticity solved here; check that loads and moduli are in one "
      "system of units (young in MPa with loads in Pa makes the body a million times too soft)");
}

// The model takes the loaded boundary Γp and the contact face Γc apart. A traction or pressure on a
// group that shares triangles with Γc (the contact group itself, or a load patch cut from the sole)
// was applied where the foundation holds the body with nothing said; said in a warning with the
// area, per load.
void warn_if_loads_on_contact(const Scene& scene, const Mesh& mesh, SolveResult& res) {
  auto key = [&](int t) {
    std::array<int, 3> k = mesh.triangles[static_cast<std::size_t>(t)];
    std::sort(k.begin(), k.end());
    return k;
  };
  std::set<std::array<int, 3>> contact;
  // Groups that are missing or not surfaces are left to the checks that name them (check_mesh_meaning).
  auto triangles = [&](const std::string& group) {
    return mesh.find_group(group, 2) ? mesh.triangles_of_group(group) : std::vector<int>();
  };
  for (const auto& group : scene.contact)
    for (const int t : triangles(group)) contact.insert(key(t));
  for (const auto& load : scene.tractions) {
    double shared = 0;
    for (const int t : triangles(load.group)) {
      if (contact.count(key(t))) shared += triangle_area(mesh, mesh.triangles[static_cast<std::size_t>(t)]);
    }
    if (shared > 0)
      res.warnings.push_back(
          std::string(load.scene_key()) + " on '" + load.group + "' acts on " + number(shared, 3) + " " +
          unit_labels(scene.output.units).length +
          "² of the contact face: the model loads Γp and lets the foundation hold Γc, two apart, "
          "so this load goes partly straight into the contact forces; put it on the faces it acts on");
  }
}

// A traction or pressure on faces whose nodes are all held in every component (on the clamped group
// itself, or on a group a [[boundary.displacement]] fixes) goes straight into the supports: the body never
// feels it, and the run said nothing (a helper's end load moved onto 'clamped': exit 0, the reaction
// swallowing it). Said per load.
void warn_if_loads_on_held_faces(const Scene& scene, const Mesh& mesh, const DofMap& dofs, SolveResult& res) {
  for (const auto& load : scene.tractions) {
    if (!mesh.find_group(load.group, 2)) continue;  // missing or not a surface: check_mesh_meaning names it
    const auto triangles = mesh.triangles_of_group(load.group);
    const bool all_held = !triangles.empty() && std::all_of(triangles.begin(), triangles.end(), [&](int t) {
      const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
      return std::all_of(tri.begin(), tri.end(), [&](int v) { return dofs.fully_fixed(v); });
    });
    if (all_held)
      res.warnings.push_back(std::string(load.scene_key()) + " on '" + load.group +
                             "' acts only on nodes whose displacement is prescribed in every component (boundary."
                             "clamped or boundary.displacement): the supports take it and the body does not feel "
                             "it (it shows in the reactions); put it on the faces it acts on");
  }
}

// A [[boundary.displacement]] holding one component at 0 is how a symmetry plane is stated; on a group
// that is no plane normal to that component it holds the faces' tangential motion too (a helper's
// y = 0 put on a roller's curved top instead of its symmetry face "sym_y": exit 0, nothing said).
// Said where the group's faces lean, area-weighted, more than acos(kSymmetryPlaneAlignment) from it.
constexpr double kSymmetryPlaneAlignment = 0.9;  // about 26°
void warn_if_symmetry_condition_off_its_plane(const Scene& scene, const Mesh& mesh, SolveResult& res) {
  static const char* const kAxis[3] = {"x", "y", "z"};
  for (const PrescribedDisplacement& d : scene.displacements) {
    int held = -1, count = 0;
    for (int c = 0; c < 3; ++c)
      if (d.value[c]) held = c, ++count;
    if (count != 1 || *d.value[held] != 0 || !d.gradient.row(held).isZero() || !mesh.find_group(d.group, 2)) continue;
    double area = 0, aligned = 0;
    for (const int t : mesh.triangles_of_group(d.group)) {
      const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
      const Eigen::Vector3d n =
          (mesh.nodes[tri[1]] - mesh.nodes[tri[0]]).cross(mesh.nodes[tri[2]] - mesh.nodes[tri[0]]);
      area += n.norm();
      aligned += std::abs(n[held]);
    }
    if (!(area > 0) || aligned >= kSymmetryPlaneAlignment * area) continue;
    res.warnings.push_back("boundary.displacement on '" + d.group + "' holds only " + kAxis[held] +
                           " = 0, as a symmetry plane does, but '" + d.group + "' is not a plane normal to " +
                           kAxis[held] + " (its faces lean " +
                           number(std::acos(std::min(1.0, aligned / area)) * 180 / std::numbers::pi, 2) +
                           "° from it on average, area-weighted): there it holds the faces' motion along them too; "
                           "check that the group is the symmetry face");
  }
}

// Two [[boundary.traction]] (or two [[boundary.pressure]]) entries on one group are added: meant where
// loads are superposed, a slip where one was copied and its group not renamed. Said in a note, so the
// sum is not a surprise (a traction beside a pressure on one group is the usual way to state both).
void note_loads_given_twice(const Scene& scene, SolveResult& res) {
  std::map<std::pair<std::string, std::string>, int> entries;  // (group, the entry's table) -> count
  for (const auto& load : scene.tractions) ++entries[{load.group, load.scene_key()}];
  for (const auto& [key, count] : entries)
    if (count > 1)
      res.notes.push_back("'" + key.first + "' has " + std::to_string(count) + " [[" + key.second +
                          "]] entries: they are added, and the load there is their sum");
}

// [friction] keys the chosen law does not read: accepted so that `--set friction.law=none` runs a
// scene written for "ramp", but not in silence (the run is frictionless, its slip_bound unused).
void note_friction_keys_not_read(const Scene& scene, SolveResult& res) {
  if (scene.friction_keys_not_read.empty()) return;
  std::string keys;
  for (const std::string& key : scene.friction_keys_not_read) keys += (keys.empty() ? "friction." : ", ") + key;
  res.notes.push_back(keys + (scene.friction_keys_not_read.size() > 1 ? " are" : " is") + " not read by law '" +
                      scene.law.name() + "' and take no part in this run");
}

// Tresca's bound F·g with g = friction.slip_bound = 0 is zero: a law given beside it has no effect, and
// the run is frictionless with nothing said but its "one frictionless QP" (a helper's ramp law, summary's
// friction_law still "ramp").
void warn_if_zero_slip_bound_drops_the_law(const Scene& scene, SolveResult& res) {
  const bool law_given = scene.law.kind != FrictionLaw::Kind::None &&
                         !(scene.law.kind == FrictionLaw::Kind::Constant && scene.law.value == 0);
  if (scene.friction_model != FrictionModel::Tresca || scene.slip_bound != 0 || !law_given) return;
  res.warnings.push_back(
      "friction.slip_bound = 0 makes Tresca's bound F·g zero everywhere: the run is frictionless "
      "and friction.law '" +
      scene.law.name() + "' takes no part in it; give g > 0 (a stress, in " +
      std::string(unit_labels(scene.output.units).stress) + "), or friction.model = \"coulomb\" for the bound F·λ_n");
}

// A body whose size, in the scene's length unit, no part solved here has: a mesh made in millimetres read
// as metres (a helper's 200 mm block under m-N-Pa: "area in contact 4e+04 m²", 5.5e11 N, and only a
// refinement warning), or one made in metres under mm-N-MPa. Linear elasticity is blind to it where the
// loads are pressures (the strains come out right), the forces and areas are not.
constexpr double kLargestPlausibleBodyMetres = 100;
constexpr double kSmallestPlausibleBodyMetres = 1e-4;
void warn_if_body_size_suggests_another_length_unit(const Scene& scene, const Mesh& mesh, SolveResult& res) {
  if (mesh.nodes.empty()) return;
  Eigen::Vector3d lo = mesh.nodes.front(), hi = lo;
  for (const Eigen::Vector3d& x : mesh.nodes) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  const double size = (hi - lo).maxCoeff();
  const bool in_mm = scene.output.units == UnitSystem::MillimetreNewtonMegapascal;
  const double metres = in_mm ? 1e-3 * size : size;
  const std::string unit = unit_labels(scene.output.units).length;
  const std::string units = "output.units = \"" + std::string(name_of(scene.output.units, kUnitSystemNames)) + "\"";
  if (metres > kLargestPlausibleBodyMetres && !in_mm)
    res.warnings.push_back("the body is " + number(size, 3) + " " + unit + " across (" + units +
                           "): if the mesh was made in millimetres, it is read here in metres and every force and "
                           "area comes out a million times too large; scale the mesh by 0.001 or state the scene in "
                           "\"mm-N-MPa\" (lengths in mm, moduli and loads in MPa)");
  if (metres < kSmallestPlausibleBodyMetres && in_mm)
    res.warnings.push_back("the body is " + number(size, 3) + " " + unit + " across (" + units +
                           "): if the mesh was made in metres, it is read here in millimetres; scale the mesh by "
                           "1000 or state the scene in \"m-N-Pa\"");
}

// Volumes meshed apart that touch over a face whose nodes they do not share (a cylinder meshed finer
// than the box it stands on, without BooleanFragments): no two nodes coincide, and nothing was said
// while the cylinder's load went to its own clamp (normal force 0 N on the box below).
void warn_if_faces_against_the_body(const Mesh& mesh, SolveResult& res) {
  const FacesAgainstTheBody touching = faces_against_the_body(mesh);
  if (touching.faces == 0) return;
  const auto& n = touching.example_nodes;
  res.warnings.push_back(std::to_string(touching.faces) +
                         " boundary face(s) of the tetrahedra lie against another part of the mesh without sharing "
                         "its nodes (e.g. the face of nodes " +
                         std::to_string(n[0]) + ", " + std::to_string(n[1]) + ", " + std::to_string(n[2]) +
                         " against tetrahedron " + std::to_string(touching.example_against) +
                         "): the mesh's volumes are not joined there and move apart as separate bodies; join them "
                         "when meshing (gmsh: BooleanFragments or Coherence with OpenCASCADE) unless they are meant "
                         "to be separate");
}

// Tetrahedra joined to the rest of the body at nodes only (mesh_checks.hpp): a tetrahedron laid over three
// nodes of a block that form none of its faces was solved in silence, the load it carries going through
// three points.
void warn_if_blocks_joined_at_nodes(const Mesh& mesh, SolveResult& res) {
  const BlocksJoinedAtNodes joined = blocks_joined_at_nodes(mesh);
  if (joined.blocks <= 0) return;
  const bool one = joined.blocks == 1;
  res.warnings.push_back(
      (one ? std::string("a block of tetrahedra meets")
           : std::to_string(joined.blocks) + " blocks of tetrahedra meet") +
      " the rest of the body at nodes only, sharing no face with it (e.g. tetrahedron " +
      std::to_string(joined.example_tet) + ", in a block of " + std::to_string(joined.example_tets) + ", joined at " +
      std::to_string(joined.example_joints) +
      " node(s)): load passes between them only through those points, so the stresses there are singular and the "
      "block's answer depends on the mesh; an element laid over nodes of the body, or volumes meshed apart and "
      "merged at a few nodes, is the usual cause: join the volumes through shared faces (gmsh: BooleanFragments) or "
      "remove the stray elements");
}

// Two nodes of the tetrahedra at one place: volumes meshed side by side without being joined (gmsh
// boxes without BooleanFragments / Coherence). Each moves on its own there, so a load on one goes
// nowhere near the other: two stacked boxes, 80 such pairs, solved with the top load going straight
// to the clamp and no contact force, with nothing said. Places are compared rounded to 1e-9 of the
// mesh's size.
void warn_if_coincident_nodes(const Mesh& mesh, SolveResult& res) {
  const std::vector<char> used = nodes_of_tets(mesh);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
    if (used[v]) lo = lo.cwiseMin(mesh.nodes[v]), hi = hi.cwiseMax(mesh.nodes[v]);
  const double unit = 1e-9 * std::max((hi - lo).norm(), std::numeric_limits<double>::min());
  std::map<std::array<long long, 3>, std::size_t> at;
  std::size_t pairs = 0, first_a = 0, first_b = 0;
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v) {
    if (!used[v]) continue;
    const Eigen::Vector3d r = ((mesh.nodes[v] - lo) / unit).array().round();
    const auto [it, fresh] =
        at.emplace(std::array<long long, 3>{static_cast<long long>(r.x()), static_cast<long long>(r.y()),
                                            static_cast<long long>(r.z())},
                   v);
    if (fresh) continue;
    if (pairs++ == 0) first_a = it->second, first_b = v;
  }
  if (pairs == 0) return warn_if_faces_against_the_body(mesh, res);
  res.warnings.push_back(std::to_string(pairs) + " node(s) of the tetrahedra lie where another one does (e.g. nodes " +
                         std::to_string(mesh.node_tags[first_a]) + " and " + std::to_string(mesh.node_tags[first_b]) +
                         "): the mesh's volumes are not joined there and move apart as separate bodies; join them when "
                         "meshing (gmsh: BooleanFragments or Coherence with OpenCASCADE) unless they are meant to be "
                         "separate");
}

// The ramp law (6.1) falls from `high` at small slips to `low`: given the other way round it rises with
// the slip (slip-strengthening), which a user may mean but more often swapped the two (accepted with
// nothing said before).
void warn_if_ramp_rises_with_slip(const Scene& scene, SolveResult& res) {
  const FrictionLaw& law = scene.law;
  if (law.kind != FrictionLaw::Kind::Ramp || !(law.high < law.low)) return;
  res.warnings.push_back("friction.high = " + number(law.high) + " is below friction.low = " + number(law.low) +
                         ": the coefficient rises from " + number(law.high) + " to " + number(law.low) +
                         " as the slip grows (the paper's law (6.1) falls from high to low); if not meant, swap them");
}

// A body a layer or two of tetrahedra thick over its contact face (FaceThickness::elements_through):
// linear tetrahedra that few through a plate or shell are far too stiff in bending, and nothing in the
// run would show it (a new user's steel shell segment 2 mm thick, its edges pushed 0.3 mm down onto the
// plane, one layer at h = 2 mm: normal force 1426 N; 1260, 679 and 632 N at h = 1.33, 1 and 0.8 mm). Said
// of any plate or shell, bent or not: a gasket pressed flat is served by one layer, a plate that bends is not.
// In the foundation's frame (solve and check both work there; a scene not in it is not measured).
constexpr double kFewestElementsThrough = 2;
// The words that mark that warning (warns_of_accuracy_only).
constexpr const char* kFewElementsThrough = " element(s) through that thickness: linear tetrahedra (P1)";
// A plate or shell: the body spans more than ten times its thickness. A compact body thin only
// towards its rims (a solid spherical cap 30 mm high on a face 143 mm across, pressed at its pole:
// median 16 mm, 1.8 elements, the force within 0.7% of a mesh twice as fine) does not bend.
constexpr double kPlateSpanOverThickness = 10;
void warn_if_few_elements_through_thickness(const Scene& scene, const FaceThicknessOnce& measured, SolveResult& res) {
  if (scene.contact.empty() || !scene.foundation.is_identity()) return;
  const FaceThickness& thickness = measured.get();
  if (!(thickness.elements_through < kFewestElementsThrough) ||
      !(kPlateSpanOverThickness * thickness.median < thickness.extent))
    return;
  const std::string unit = std::string(" ") + unit_labels(scene.output.units).length;
  res.warnings.push_back(
      "the body is " + number(thickness.median, 3) + unit +
      " thick over most of Γc (the median) and the mesh has about " + number(thickness.elements_through, 2) +
      kFewElementsThrough +
      " that few through a plate or shell are far too "
      "stiff in bending, so if the body bends its deflection comes out too small and its contact forces off (a "
      "shell segment with one element through: twice the force of a fine mesh; a gasket pressed flat is not "
      "concerned); mesh at least three or four elements through the thickness, or check that the answer changes "
      "little when h is halved");
}

}  // namespace

void warn_about_inputs(const Scene& scene, const Mesh& mesh, const DofMap& dofs, const TetMaterials& materials,
                       const FaceThicknessOnce& thickness, SolveResult& res) {
  warn_if_nearly_incompressible(mesh, materials, res);
  warn_if_beyond_any_solid(scene, mesh, materials, res);
  warn_if_loads_beyond_linear_strain(scene, mesh, materials, res);
  warn_if_loads_on_contact(scene, mesh, res);
  warn_if_loads_on_held_faces(scene, mesh, dofs, res);
  note_loads_given_twice(scene, res);
  warn_if_symmetry_condition_off_its_plane(scene, mesh, res);
  note_friction_keys_not_read(scene, res);
  warn_if_zero_slip_bound_drops_the_law(scene, res);
  warn_if_body_size_suggests_another_length_unit(scene, mesh, res);
  warn_if_coincident_nodes(mesh, res);
  warn_if_blocks_joined_at_nodes(mesh, res);
  warn_if_ramp_rises_with_slip(scene, res);
  warn_if_few_elements_through_thickness(scene, thickness, res);
}

bool warns_of_accuracy_only(const std::string& warning) {
  return warning.find(kFewElementsThrough) != std::string::npos;
}

}  // namespace contact3d
