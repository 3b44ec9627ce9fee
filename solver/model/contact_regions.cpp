#include "model/contact_regions.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>
#include <utility>

#include "fem/elasticity.hpp"

namespace contact3d {

namespace {

// Tolerance under which two heights above the foundation are one: the round-off of a flat face's nodes
// (mesh files keep 15 to 17 digits; the contact face's own plane tolerance is the same 1e-8), far below
// a rounded edge's rise, and small enough that the nearly flat middle of a crowned face (10 µm over
// 0.2 m) is no level of its own.
double level_tolerance(const ContactFace& face) {
  double largest_gap = 0;
  for (const auto& t : face.triangles)
    for (const int v : t) largest_gap = std::max(largest_gap, std::abs(face.gap[static_cast<std::size_t>(v)]));
  return 1e-8 * std::max((face.hi - face.lo).norm(), largest_gap);
}

double projected_area(const Mesh& mesh, const std::array<int, 3>& t) {
  const Eigen::Vector2d a = mesh.nodes[t[0]].head<2>(), b = mesh.nodes[t[1]].head<2>(), c = mesh.nodes[t[2]].head<2>();
  return 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
}

// (E, ν) of each contact triangle's tetrahedron ([material] where the scene has no regions).
std::vector<std::pair<double, double>> triangle_materials(const Scene& scene, const Mesh& mesh,
                                                          const ContactFace& face) {
  std::vector<std::pair<double, double>> material(face.triangles.size(),
                                                  {scene.material.young, scene.material.poisson});
  if (scene.regions.empty()) return material;
  const TetMaterials materials = tet_materials(scene, mesh);
  const std::vector<int> tet = tetrahedra_of_faces(mesh, face.triangles);
  for (std::size_t t = 0; t < tet.size(); ++t)
    if (tet[t] >= 0) {
      const Material& m = materials[static_cast<std::size_t>(tet[t])];
      material[t] = {m.young, m.poisson};
    }
  return material;
}

}  // namespace

std::vector<int> triangle_levels(const Mesh& mesh, const ContactFace& face) {
  const double tol = level_tolerance(face);
  std::vector<double> height(face.triangles.size(), 0.0);
  std::vector<std::size_t> flat;
  for (std::size_t t = 0; t < face.triangles.size(); ++t) {
    const auto& tri = face.triangles[t];
    const double g0 = face.gap[static_cast<std::size_t>(tri[0])], g1 = face.gap[static_cast<std::size_t>(tri[1])],
                 g2 = face.gap[static_cast<std::size_t>(tri[2])];
    if (std::max({g0, g1, g2}) - std::min({g0, g1, g2}) > tol) continue;
    height[t] = (g0 + g1 + g2) / 3;
    flat.push_back(t);
  }
  // Heights sorted: a new level starts where the next height rises by more than the tolerance. A level
  // of under 1% of the face's area is none (three nodes of a curved face that happen to lie at one height).
  std::sort(flat.begin(), flat.end(), [&](std::size_t a, std::size_t b) { return height[a] < height[b]; });
  std::vector<int> level(face.triangles.size(), kNoLevel);
  int levels = 0;
  for (std::size_t first = 0; first < flat.size();) {
    std::size_t end = first + 1;
    while (end < flat.size() && height[flat[end]] - height[flat[end - 1]] <= tol) ++end;
    double area = 0;
    for (std::size_t k = first; k < end; ++k) area += projected_area(mesh, face.triangles[flat[k]]);
    if (area >= 0.01 * face.area) {
      for (std::size_t k = first; k < end; ++k) level[flat[k]] = levels;
      ++levels;
    }
    first = end;
  }
  return level;
}

std::vector<int> contact_triangle_regions(const Scene& scene, const Mesh& mesh, const ContactFace& face) {
  const std::vector<std::pair<double, double>> material = triangle_materials(scene, mesh, face);
  const std::vector<int> level = triangle_levels(mesh, face);
  std::map<std::tuple<double, double, int>, int> ids;  // (E, ν, level) -> region
  std::vector<int> region;
  region.reserve(face.triangles.size());
  for (std::size_t t = 0; t < face.triangles.size(); ++t) {
    const auto key = std::tuple(material[t].first, material[t].second, level[t]);
    region.push_back(ids.emplace(key, static_cast<int>(ids.size())).first->second);
  }
  if (ids.size() <= 1) return {};
  return region;
}

}  // namespace contact3d
