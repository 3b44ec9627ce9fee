#include "model/contact_regions.hpp"

#include <map>
#include <utility>

#include "fem/elasticity.hpp"

namespace contact3d {

std::vector<int> contact_triangle_regions(const Scene& scene, const Mesh& mesh, const ContactFace& face) {
  if (scene.regions.empty()) return {};
  const TetMaterials materials = tet_materials(scene, mesh);
  const std::vector<int> tet = tetrahedra_of_faces(mesh, face.triangles);
  std::map<std::pair<double, double>, int> ids;  // (E, ν) -> region
  std::vector<int> region;
  region.reserve(tet.size());
  for (const int e : tet) {
    const Material& m = e >= 0 ? materials[static_cast<std::size_t>(e)] : scene.material;
    region.push_back(ids.emplace(std::pair(m.young, m.poisson), static_cast<int>(ids.size())).first->second);
  }
  return region;
}

}  // namespace contact3d
