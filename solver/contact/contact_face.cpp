#include "contact/contact_face.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "mesh/mesh_checks.hpp"

namespace contact3d {

namespace {

bool held_in_every_node(const std::array<int, 3>& tri, const DofMap& dofs) {
  return std::all_of(tri.begin(), tri.end(), [&](int v) { return dofs.fully_fixed(v); });
}

// A contact node whose normal displacement a condition prescribes below the plane: non-penetration holds
// there only as its cells' averages (the node's own place is the condition's), recorded for a warning that
// names the condition (the paper's brick with its end pushed 50 µm down got warnings blaming the cells).
void note_prescribed_below_plane(const DofMap& dofs, int v, double gap, double tol, ContactFace& face) {
  if (!(dofs.fixed[v] & 4)) return;
  const double depth = -(gap + dofs.prescribed[3 * v + 2]);
  if (!(depth > tol)) return;
  auto& below = face.prescribed_below;
  if (below.nodes == 0 || depth > below.depth) {
    below.depth = depth;
    below.deepest = v;
    const int by = dofs.fixed_by[3 * v + 2];
    below.condition = by >= 0 ? dofs.conditions[by] : std::string("a prescribed displacement");
  }
  ++below.nodes;
}

}  // namespace

Eigen::Vector2d median_extents(const Mesh& mesh, const std::vector<std::array<int, 3>>& triangles) {
  if (triangles.empty()) return Eigen::Vector2d::Zero();
  std::vector<double> extent_x, extent_y;
  for (const auto& tri : triangles) {
    Eigen::Vector2d tlo = mesh.nodes[tri[0]].head<2>(), thi = tlo;
    for (int k = 1; k < 3; ++k) {
      tlo = tlo.cwiseMin(mesh.nodes[tri[k]].head<2>());
      thi = thi.cwiseMax(mesh.nodes[tri[k]].head<2>());
    }
    extent_x.push_back(thi.x() - tlo.x());
    extent_y.push_back(thi.y() - tlo.y());
  }
  auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  return {median(extent_x), median(extent_y)};
}

Eigen::Vector2d element_sizes_xy(const Mesh& mesh, const std::vector<std::array<int, 3>>& triangles) {
  const Eigen::Vector2d extents = median_extents(mesh, triangles);
  if (triangles.empty() || !(extents.prod() > 0)) return extents;
  std::vector<double> areas;
  areas.reserve(triangles.size());
  for (const auto& tri : triangles) {
    const Eigen::Vector2d a = mesh.nodes[tri[1]].head<2>() - mesh.nodes[tri[0]].head<2>();
    const Eigen::Vector2d b = mesh.nodes[tri[2]].head<2>() - mesh.nodes[tri[0]].head<2>();
    areas.push_back(0.5 * std::abs(a.x() * b.y() - a.y() * b.x()));
  }
  std::nth_element(areas.begin(), areas.begin() + static_cast<std::ptrdiff_t>(areas.size() / 2), areas.end());
  // A triangle whose box is hx × hy covers about hx·hy/2 (a right triangle: exactly). Far less means
  // elements stretched along directions that turn across the face, which neither axis follows.
  const double shrink = std::sqrt(2.0 * areas[areas.size() / 2] / extents.prod());
  return shrink < kTurningStretchShrink ? Eigen::Vector2d(shrink * extents) : extents;
}

ContactFace make_contact_face(const Mesh& mesh, const std::vector<std::string>& contact_groups, const DofMap& dofs) {
  ContactFace face;
  if (mesh.nodes.empty()) throw InputError("the mesh has no nodes");
  Eigen::Vector3d lo = mesh.nodes.front(), hi = mesh.nodes.front();
  for (const auto& x : mesh.nodes) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  // Below the plane by more than plane_tol: an initial penetration, refused; less, rounding of the mesh's
  // coordinates (a mesh written with 8 digits and turned onto the plane sat 5.6e-8 m below it on a body of
  // 0.6 m, and a plane point given to 10 digits 1e-9 m above a face, both refused), taken as 0. Heights
  // above the plane by more than gap_snap are the initial gap d, however small: a face lifted 2e-8 on a
  // body of diagonal 3.3 had been put back on the plane, its normal pressure 3e-4 off.
  const double diagonal = std::max((hi - lo).norm(), 1e-300);
  const double plane_tol = kPenetrationRounding * diagonal, gap_snap = 1e-12 * diagonal;

  std::set<std::array<int, 3>> seen;
  for (const auto& name : contact_groups) {
    const auto tris = mesh.triangles_of_group(name);
    if (tris.empty()) throw InputError("contact group '" + name + "' has no triangles");
    for (int t : tris) {
      const auto& tri = mesh.triangles[t];
      for (int v : tri)
        if (mesh.nodes[v].z() < -plane_tol)
          throw InputError("contact group '" + name + "': triangle " + std::to_string(mesh.triangle_tags[t]) +
                           " has a node at z = " + number(mesh.nodes[v].z()) +
                           " below the foundation plane z = 0 (initial penetration); Γc must lie on or above it");
      std::array<int, 3> key = tri;
      std::sort(key.begin(), key.end());
      if (!seen.insert(key).second) continue;
      if (held_in_every_node(tri, dofs)) {
        ++face.held_triangles;
        face.held_area += triangle_area(mesh, tri);
      } else {
        face.triangles.push_back(tri);
      }
    }
  }
  if (face.triangles.empty())
    throw InputError("every node of the contact groups lies on the clamped boundary Γu: Γc has no contact node");
  // A push through the plane beyond the initial penetration's rounding is said (a clamp tilted by 1e-6 rad
  // on the paper's brick dips its edge on Γc 2e-6 m, 6e-7 of its size: not).
  std::vector<char> counted(mesh.nodes.size(), 0);
  for (const auto& name : contact_groups)
    for (int t : mesh.triangles_of_group(name))
      for (int v : mesh.triangles[t])
        if (!counted[v]++) note_prescribed_below_plane(dofs, v, std::max(mesh.nodes[v].z(), 0.0), plane_tol, face);
  face.contact_index.assign(mesh.nodes.size(), -1);
  face.gap.assign(mesh.nodes.size(), 0.0);
  for (const auto& tri : face.triangles)
    for (int v : tri) {
      face.gap[v] = mesh.nodes[v].z() <= gap_snap ? 0.0 : mesh.nodes[v].z();  // flat stays exactly flat
      if (-mesh.nodes[v].z() > gap_snap) face.rounded_up = std::max(face.rounded_up, -mesh.nodes[v].z());
    }
  std::vector<double> shortest;
  face.lo = mesh.nodes[face.triangles[0][0]].head<2>();
  face.hi = face.lo;
  for (const auto& tri : face.triangles) {
    double e = INFINITY;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d p = mesh.nodes[tri[k]].head<2>();
      face.lo = face.lo.cwiseMin(p);
      face.hi = face.hi.cwiseMax(p);
      e = std::min(e, (p - mesh.nodes[tri[(k + 1) % 3]].head<2>()).norm());
      if (!dofs.fully_fixed(tri[k])) face.contact_index[tri[k]] = 0;
    }
    shortest.push_back(e);
    const Eigen::Vector2d a = mesh.nodes[tri[1]].head<2>() - mesh.nodes[tri[0]].head<2>();
    const Eigen::Vector2d b = mesh.nodes[tri[2]].head<2>() - mesh.nodes[tri[0]].head<2>();
    face.area += 0.5 * std::abs(a.x() * b.y() - a.y() * b.x());
  }
  std::nth_element(shortest.begin(), shortest.begin() + shortest.size() / 2, shortest.end());
  face.h = shortest[shortest.size() / 2];
  face.h_xy = element_sizes_xy(mesh, face.triangles).cwiseMax(face.h);
  if (!(face.area > 0)) throw InputError("the contact groups have zero total area (degenerate triangles)");
  for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
    if (face.contact_index[v] == 0) {
      face.contact_index[v] = static_cast<int>(face.nodes.size());
      face.nodes.push_back(static_cast<int>(v));
    }
  return face;
}

std::string prescribed_below_plane_warning(const Mesh& mesh, const ContactFace& face) {
  const auto& below = face.prescribed_below;
  if (below.nodes == 0) return {};
  return below.condition + " moves " + std::to_string(below.nodes) +
         " node(s) of the contact face below the foundation plane, node " +
         std::to_string(mesh.node_tags[static_cast<std::size_t>(below.deepest)]) + " by " + number(below.depth) +
         ": the contact cannot hold them (their place is the condition's), so non-penetration holds there only "
         "as the cells' averages and the penetration reported is the condition's, not the cells'; if the face is "
         "not meant to go through the foundation, prescribe a normal displacement that keeps it on or above the "
         "plane, or take the faces touching Γc out of the condition's group";
}

}  // namespace contact3d
