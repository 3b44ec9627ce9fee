#include "contact/face_thickness.hpp"

#include "contact/contact_face.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <utility>

namespace contact3d {
namespace {

// The boundary faces that face up (outward normal with a positive z part), bucketed by a uniform grid
// over their projection onto the plane, so that a vertical ray visits only the faces over its point.
class UpwardFaces {
 public:
  explicit UpwardFaces(const Mesh& mesh) : mesh_(mesh) {
    for (const auto& f : boundary_faces(mesh)) {
      const Eigen::Vector3d n = (mesh.nodes[f[1]] - mesh.nodes[f[0]]).cross(mesh.nodes[f[2]] - mesh.nodes[f[0]]);
      if (n.z() > 1e-9 * n.norm()) faces_.push_back(f);
    }
    if (faces_.empty()) return;
    lo_ = hi_ = mesh.nodes[faces_.front()[0]].head<2>();
    for (const auto& f : faces_)
      for (int v : f) {
        lo_ = lo_.cwiseMin(mesh.nodes[v].head<2>());
        hi_ = hi_.cwiseMax(mesh.nodes[v].head<2>());
      }
    const Eigen::Vector2d extent = (hi_ - lo_).cwiseMax(1e-300);
    const double side = std::sqrt(extent.x() * extent.y() / static_cast<double>(faces_.size()));
    const auto buckets = [&](double length) {
      return std::clamp(static_cast<int>(std::ceil(length / std::max(side, 1e-300))), 1, 4096);
    };
    nx_ = buckets(extent.x());
    ny_ = buckets(extent.y());
    // About one bucket per face; a footprint degenerate in one direction must not ask for 4096².
    const long most = 4 * static_cast<long>(faces_.size()) + 16;
    if (static_cast<long>(nx_) * ny_ > most) ny_ = static_cast<int>(std::max(1L, most / nx_));
    grid_.resize(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_));
    for (std::size_t i = 0; i < faces_.size(); ++i) {
      Eigen::Vector2d flo = mesh.nodes[faces_[i][0]].head<2>(), fhi = flo;
      for (int v : faces_[i]) {
        flo = flo.cwiseMin(mesh.nodes[v].head<2>());
        fhi = fhi.cwiseMax(mesh.nodes[v].head<2>());
      }
      const auto [ix0, iy0] = bucket(flo);
      const auto [ix1, iy1] = bucket(fhi);
      for (int iy = iy0; iy <= iy1; ++iy)
        for (int ix = ix0; ix <= ix1; ++ix) grid_[index(ix, iy)].push_back(static_cast<int>(i));
    }
  }

  // The height of the lowest face above `p` (z > p.z + above), or infinity where the ray meets none.
  double lowest_above(const Eigen::Vector3d& p, double above) const {
    double best = std::numeric_limits<double>::infinity();
    if (faces_.empty()) return best;
    const auto [ix, iy] = bucket(p.head<2>());
    for (int i : grid_[index(ix, iy)]) {
      const double z = height_over(faces_[static_cast<std::size_t>(i)], p.head<2>());
      if (z > p.z() + above) best = std::min(best, z);
    }
    return best;
  }

 private:
  std::pair<int, int> bucket(const Eigen::Vector2d& q) const {
    const Eigen::Vector2d t = (q - lo_).cwiseQuotient((hi_ - lo_).cwiseMax(1e-300));
    return {std::clamp(static_cast<int>(t.x() * nx_), 0, nx_ - 1),
            std::clamp(static_cast<int>(t.y() * ny_), 0, ny_ - 1)};
  }
  std::size_t index(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(ix);
  }
  // z of the face's plane over q where q lies in the face's projection (edges included), else -infinity.
  double height_over(const std::array<int, 3>& f, const Eigen::Vector2d& q) const {
    const Eigen::Vector3d &a = mesh_.nodes[f[0]], &b = mesh_.nodes[f[1]], &c = mesh_.nodes[f[2]];
    const Eigen::Vector2d ab = (b - a).head<2>(), ac = (c - a).head<2>(), aq = q - a.head<2>();
    const double det = ab.x() * ac.y() - ab.y() * ac.x();  // > 0: the face points up
    const double s = (aq.x() * ac.y() - aq.y() * ac.x()) / det;
    const double t = (ab.x() * aq.y() - ab.y() * aq.x()) / det;
    constexpr double tol = 1e-9;
    if (s < -tol || t < -tol || s + t > 1 + tol) return -std::numeric_limits<double>::infinity();
    return a.z() + s * (b.z() - a.z()) + t * (c.z() - a.z());
  }

  const Mesh& mesh_;
  std::vector<std::array<int, 3>> faces_;
  Eigen::Vector2d lo_ = Eigen::Vector2d::Zero(), hi_ = Eigen::Vector2d::Zero();
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> grid_;
};

// A contact triangle whose upward ray met a face: the body's thickness over its centroid.
struct MeasuredTriangle {
  std::array<int, 3> sorted_nodes;
  double thickness;
  double projected_area;  // onto the foundation's plane: the weight of its thickness
};

// The value below which lies half the total weight.
double weighted_median(std::vector<std::pair<double, double>> value_weight) {
  std::sort(value_weight.begin(), value_weight.end());
  double total = 0;
  for (const auto& vw : value_weight) total += vw.second;
  double below = 0;
  for (const auto& [value, weight] : value_weight) {
    below += weight;
    if (below >= 0.5 * total) return value;
  }
  return value_weight.back().first;
}

// Per contact triangle (sorted node key), the height of the tetrahedron standing on it: its fourth
// node's distance above the triangle's plane.
std::map<std::array<int, 3>, double> heights_over(const Mesh& mesh, const std::set<std::array<int, 3>>& triangles) {
  std::map<std::array<int, 3>, double> heights;
  std::vector<char> on_face(mesh.nodes.size(), 0);
  for (const auto& t : triangles)
    for (int v : t) on_face[static_cast<std::size_t>(v)] = 1;
  for (const auto& tet : mesh.tets) {
    int touching = 0;  // only a tetrahedron with three nodes on the face can stand on one of its triangles
    for (int v : tet) touching += on_face[static_cast<std::size_t>(v)];
    if (touching < 3) continue;
    for (int apex = 0; apex < 4; ++apex) {
      std::array<int, 3> face{};
      for (int k = 0, j = 0; k < 4; ++k)
        if (k != apex) face[static_cast<std::size_t>(j++)] = tet[static_cast<std::size_t>(k)];
      std::sort(face.begin(), face.end());
      if (!triangles.count(face)) continue;
      const Eigen::Vector3d &a = mesh.nodes[face[0]], &b = mesh.nodes[face[1]], &c = mesh.nodes[face[2]];
      const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
      heights[face] = std::abs(n.dot(mesh.nodes[tet[static_cast<std::size_t>(apex)]] - a));
    }
  }
  return heights;
}

}  // namespace

FaceThickness measure_face_thickness(const Mesh& mesh, const std::vector<std::string>& contact_groups) {
  FaceThickness out;
  std::set<std::array<int, 3>> seen;
  std::vector<std::array<int, 3>> triangles;
  for (const auto& name : contact_groups)
    for (int t : mesh.triangles_of_group(name)) {
      std::array<int, 3> key = mesh.triangles[static_cast<std::size_t>(t)];
      std::sort(key.begin(), key.end());
      if (seen.insert(key).second) triangles.push_back(mesh.triangles[static_cast<std::size_t>(t)]);
    }
  out.triangles = static_cast<int>(triangles.size());
  if (triangles.empty()) return out;

  Eigen::Vector3d lo = mesh.nodes.front(), hi = lo;
  for (const auto& x : mesh.nodes) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const double above = 1e-12 * (hi - lo).norm();  // rounding: the contact triangle's own plane
  out.extent = (hi - lo).head<2>().maxCoeff();
  const UpwardFaces upward(mesh);
  std::vector<MeasuredTriangle> measured;  // the triangles whose ray met a face
  for (const auto& tri : triangles) {
    const Eigen::Vector3d &a = mesh.nodes[tri[0]], &b = mesh.nodes[tri[1]], &c = mesh.nodes[tri[2]];
    const Eigen::Vector3d centroid = (a + b + c) / 3;
    const double top = upward.lowest_above(centroid, above);
    if (!std::isfinite(top)) continue;
    std::array<int, 3> key = tri;
    std::sort(key.begin(), key.end());
    measured.push_back({key, top - centroid.z(), 0.5 * std::abs((b - a).cross(c - a).z())});
  }
  const Eigen::Vector2d extents = median_extents(mesh, triangles);
  out.element_size = std::sqrt(extents.x() * extents.y());
  out.measured = static_cast<int>(measured.size());
  if (measured.empty()) return out;
  std::vector<std::pair<double, double>> thickness_area;
  for (const MeasuredTriangle& m : measured) thickness_area.emplace_back(m.thickness, m.projected_area);
  out.median = weighted_median(std::move(thickness_area));
  const std::map<std::array<int, 3>, double> heights = heights_over(mesh, seen);
  std::vector<std::pair<double, double>> layers_area;
  for (const MeasuredTriangle& m : measured) {
    const auto it = heights.find(m.sorted_nodes);
    if (it != heights.end() && it->second > 0) layers_area.emplace_back(m.thickness / it->second, m.projected_area);
  }
  if (!layers_area.empty()) out.elements_through = weighted_median(std::move(layers_area));
  return out;
}

}  // namespace contact3d
