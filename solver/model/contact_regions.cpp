#include "model/contact_regions.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <tuple>

#include "fem/dof_map.hpp"
#include "fem/elasticity.hpp"

namespace contact3d {

std::vector<int> contact_triangle_regions(const Scene& scene, const Mesh& mesh, const ContactFace& face) {
  const BodyParts parts = body_parts(mesh);
  if (scene.regions.empty() && parts.count() <= 1) return {};
  const TetMaterials materials = tet_materials(scene, mesh);
  const auto sorted = [](std::array<int, 3> t) {
    std::sort(t.begin(), t.end());
    return t;
  };
  std::map<std::array<int, 3>, std::size_t> tet_of_face;  // a contact triangle's tetrahedron
  for (const auto& t : face.triangles) tet_of_face.emplace(sorted(t), mesh.tets.size());
  for (std::size_t e = 0; e < mesh.tets.size(); ++e)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> key{};
      for (int a = 0, k = 0; a < 4; ++a)
        if (a != skip) key[k++] = mesh.tets[e][a];
      if (auto it = tet_of_face.find(sorted(key)); it != tet_of_face.end()) it->second = e;
    }
  std::map<std::tuple<int, double, double>, int> ids;
  std::vector<int> region;
  for (const auto& t : face.triangles) {
    const std::size_t e = tet_of_face[sorted(t)];
    const Material& m = e < mesh.tets.size() ? materials[e] : scene.material;
    const auto key = std::tuple(parts.of_node[static_cast<std::size_t>(t[0])], m.young, m.poisson);
    region.push_back(ids.emplace(key, static_cast<int>(ids.size())).first->second);
  }
  return region;
}

}  // namespace contact3d
