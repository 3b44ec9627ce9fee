#include "model/solution_fields.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "base/multiplier_layout.hpp"
#include "contact/partition.hpp"

namespace contact3d {

bool has_friction(int n_cells, const Eigen::VectorXd& lambda) { return n_cells > 0 && lambda.size() == 3 * n_cells; }

std::vector<int> cell_status(int n_cells, const Eigen::VectorXd& lambda, const Eigen::VectorXd& radius) {
  std::vector<int> status(n_cells, kSeparated);
  if (n_cells == 0) return status;
  const MultiplierLayout at{n_cells, has_friction(n_cells, lambda)};
  const double pmax = lambda.head(n_cells).maxCoeff();
  for (int i = 0; i < n_cells; ++i) {
    if (lambda[at.normal(i)] <= 1e-6 * pmax)
      status[i] = kSeparated;
    else if (at.with_friction && std::hypot(lambda[at.t1(i)], lambda[at.t2(i)]) >= (1 - 1e-3) * radius[i])
      status[i] = kSlip;
    else
      status[i] = kStick;
  }
  return status;
}

namespace {

// The multipliers are forces per unit area of Γc's projection onto the foundation plane (the cells of
// T_H partition that projection); a traction drawn on Γc itself is per unit of its own area. Per contact
// node: the projected area of its triangles over their area (1 on a flat face; on a curved one less,
// the cosine of the face's slope, so that the written tractions integrated over the written surface
// give the contact force of summary.json: on a half-cylinder's side they gave 2.35 times its friction).
Eigen::VectorXd projected_over_surface_area(const Mesh& mesh, const SolveResult& res) {
  const Eigen::Vector3d normal = res.frame.to_global(Eigen::Vector3d::UnitZ());
  Eigen::VectorXd projected = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mesh.nodes.size()));
  Eigen::VectorXd surface = projected;
  for (const auto& tri : res.face.triangles) {
    const Eigen::Vector3d& a = mesh.nodes[static_cast<std::size_t>(tri[0])];
    const Eigen::Vector3d area =
        (mesh.nodes[static_cast<std::size_t>(tri[1])] - a).cross(mesh.nodes[static_cast<std::size_t>(tri[2])] - a);
    for (const int v : tri) {
      projected[v] += std::abs(area.dot(normal));
      surface[v] += area.norm();
    }
  }
  Eigen::VectorXd ratio = Eigen::VectorXd::Ones(projected.size());
  for (Eigen::Index v = 0; v < ratio.size(); ++v)
    if (surface[v] > 0) ratio[v] = projected[v] / surface[v];
  return ratio;
}

}  // namespace

ContactNodeFields contact_node_fields(const Mesh& mesh, const Scene& scene, const SolveResult& res,
                                      const StateView& s) {
  const std::size_t nn = mesh.nodes.size();
  ContactNodeFields nf{Eigen::VectorXd::Zero(nn), Eigen::VectorXd::Zero(nn), Eigen::VectorXd::Zero(nn),
                       Eigen::VectorXd::Zero(nn), Eigen::VectorXd::Zero(nn), std::vector<int>(nn, kSeparated)};
  const int r = res.n_cells;
  if (r == 0) return nf;
  const MultiplierLayout at{r, has_friction(r, s.lambda)};
  const std::vector<int> cs = cell_status(r, s.lambda, s.radius);
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(nn);
  std::vector<std::array<double, 3>> status_weight(nn, {0.0, 0.0, 0.0});
  const auto rows = cell_node_weights(res.face, res.partition);
  for (int i = 0; i < r; ++i)
    for (const auto& [node, w] : rows[i]) {
      weight[node] += w;
      status_weight[node][cs[i]] += w;
      nf.pressure[node] += w * s.lambda[at.normal(i)];
      if (at.with_friction) {
        nf.traction_t1[node] += w * s.lambda[at.t1(i)];
        nf.traction_t2[node] += w * s.lambda[at.t2(i)];
        nf.radius[node] += w * s.radius[i];
      }
    }
  const Eigen::VectorXd per_surface = projected_over_surface_area(mesh, res);
  for (std::size_t v = 0; v < nn; ++v) {
    if (weight[v] <= 0) continue;
    const double to_surface = per_surface[static_cast<Eigen::Index>(v)] / weight[v];
    nf.pressure[v] *= to_surface;
    nf.traction_t1[v] *= to_surface;
    nf.traction_t2[v] *= to_surface;
    nf.radius[v] *= to_surface;
    const double slip = res.frame.to_local(s.u.segment<3>(3 * v)).head<2>().norm();
    nf.friction[v] = scene.frictionless() ? 0.0 : scene.law(slip);
    // The status the node's pressure comes from: separated only where no pressed cell carries part
    // of its hat function (its pressure is then 0), else stick or slip, whichever of those cells
    // carry more of it (ties go to slip). A majority over all cells would call the edge node of a
    // pressed sole "separated" while reporting the sole's pressure peak there; averaging the traction
    // vectors would call a node between slipping cells whose λ_t point different ways "stick".
    const auto& sw = status_weight[v];
    nf.status[v] = sw[kSlip] + sw[kStick] <= 0 ? kSeparated : sw[kSlip] >= sw[kStick] ? kSlip : kStick;
  }
  return nf;
}

Eigen::Matrix3d TetStress::tensor(std::size_t tet) const {
  const auto& v = voigt[tet];
  Eigen::Matrix3d s;
  s << v[0], v[5], v[4],  //
      v[5], v[1], v[3],   //
      v[4], v[3], v[2];
  return s;
}

namespace {

// The strain of tetrahedron e under u (Voigt order, engineering shears; constant on a P1 tet).
Eigen::Matrix<double, 6, 1> tet_strain(const Mesh& mesh, const Eigen::VectorXd& u, std::size_t e) {
  const auto& t = mesh.tets[e];
  const TetCoords x{mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]], mesh.nodes[t[3]]};
  Eigen::Matrix<double, 12, 1> ue;
  for (int a = 0; a < 4; ++a) ue.segment<3>(3 * a) = u.segment<3>(3 * t[a]);
  return strain_matrix(x) * ue;
}

}  // namespace

TetStress tet_stresses(const Mesh& mesh, const TetMaterials& materials, const Eigen::VectorXd& u) {
  TetStress out;
  out.voigt.resize(mesh.tets.size());
  out.von_mises.resize(mesh.tets.size());
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const Eigen::Matrix<double, 6, 1> s = hooke_matrix(materials[e]) * tet_strain(mesh, u, e);
    out.voigt[e] = s;
    out.von_mises[e] = std::sqrt(
        0.5 * ((s[0] - s[1]) * (s[0] - s[1]) + (s[1] - s[2]) * (s[1] - s[2]) + (s[2] - s[0]) * (s[2] - s[0])) +
        3 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
  }
  return out;
}

StrainPeak largest_strain(const Mesh& mesh, const Eigen::VectorXd& u) {
  StrainPeak peak;
  std::vector<std::pair<double, double>> strain_volume;  // per tetrahedron
  strain_volume.reserve(mesh.tets.size());
  double total_volume = 0;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    const Eigen::Matrix<double, 6, 1> v = tet_strain(mesh, u, e);
    Eigen::Matrix3d strain;
    strain << v[0], v[5] / 2, v[4] / 2, v[5] / 2, v[1], v[3] / 2, v[4] / 2, v[3] / 2, v[2];
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> principal;
    principal.computeDirect(strain, Eigen::EigenvaluesOnly);
    const double largest = principal.eigenvalues().cwiseAbs().maxCoeff();
    if (largest > peak.value) peak.value = largest, peak.tet = e;
    const auto& t = mesh.tets[e];
    const double volume = std::abs((mesh.nodes[t[1]] - mesh.nodes[t[0]])
                                       .cross(mesh.nodes[t[2]] - mesh.nodes[t[0]])
                                       .dot(mesh.nodes[t[3]] - mesh.nodes[t[0]])) /
                          6;
    if (std::isfinite(largest)) strain_volume.emplace_back(largest, volume);  // NaN would break the sort below
    total_volume += volume;
  }
  std::sort(strain_volume.begin(), strain_volume.end());
  double below = 0;
  for (const auto& [strain, volume] : strain_volume) {
    peak.bulk = strain;
    below += volume;
    if (below >= 0.99 * total_volume) break;
  }
  return peak;
}

double plane_gap(const Mesh& mesh, const FoundationFrame& frame, const Eigen::VectorXd& u, int v) {
  return frame.to_local_point(mesh.nodes[v]).z() + frame.to_local(u.segment<3>(3 * v)).z();
}

Eigen::Vector3d tangential_part(const FoundationFrame& frame, const Eigen::Vector3d& local) {
  return frame.to_global(Eigen::Vector3d(local.x(), local.y(), 0.0));
}

ContactResultants contact_resultants(const SolveResult& res, const StateView& s) {
  ContactResultants out;
  const int r = res.n_cells;
  if (r == 0) return out;
  const MultiplierLayout at{r, has_friction(r, s.lambda)};
  const std::vector<int> status = cell_status(r, s.lambda, s.radius);
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double area = 0;
  for (const auto& c : res.partition.cells) {
    centre += c.area * c.centroid;
    area += c.area;
  }
  if (area > 0) centre /= area;
  for (int i = 0; i < r; ++i) {
    const auto& c = res.partition.cells[i];
    out.area[status[i]] += c.area;
    out.normal += c.area * s.lambda[at.normal(i)];
    if (!at.with_friction) continue;
    out.t1 += c.area * s.lambda[at.t1(i)];
    out.t2 += c.area * s.lambda[at.t2(i)];
    // The foundation's friction on the body about the centroid, along the plane's normal.
    const Eigen::Vector2d arm = c.centroid - centre;
    out.friction_torque -= c.area * (arm.x() * s.lambda[at.t2(i)] - arm.y() * s.lambda[at.t1(i)]);
  }
  return out;
}

Eigen::Vector3d contact_force_in_plane_frame(const SolveResult& res) {
  const ContactResultants cr = contact_resultants(res, final_state(res));
  return {-cr.t1, -cr.t2, cr.normal};
}

}  // namespace contact3d
