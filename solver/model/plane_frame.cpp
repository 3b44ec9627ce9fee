#include "model/plane_frame.hpp"

#include <cmath>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "mesh/mesh_checks.hpp"
#include "model/contact_solver.hpp"

namespace contact3d {
namespace {

const char* const kAxis[3] = {"x", "y", "z"};

// A condition on some components in the user's axes, expressed on the plane frame's axes and at
// the frame's points x' (x = Rᵀx' + p, so u_c(x) = value_c + g_c·x = (value_c + g_c·p) + (R g_c)·x').
PrescribedDisplacement rotate_condition(const PrescribedDisplacement& given, const FoundationFrame& f) {
  const Eigen::Matrix3d& R = f.rotation;
  PrescribedDisplacement out{given.group, {}};
  if (given.value[0] && given.value[1] && given.value[2]) {
    const Eigen::Vector3d v =
        R * (Eigen::Vector3d(*given.value[0], *given.value[1], *given.value[2]) + given.gradient * f.point);
    for (int k = 0; k < 3; ++k) out.value[k] = v[k];
    out.gradient = R * given.gradient * R.transpose();
    return out;
  }
  for (int c = 0; c < 3; ++c) {
    if (!given.value[c]) continue;
    const Eigen::Vector3d axis = R.col(c);  // e_c in the plane's frame
    int k = 0;
    axis.cwiseAbs().maxCoeff(&k);
    if (std::abs(axis[k]) < 1 - 1e-12)
      throw InputError("boundary.displacement '" + given.group + "': the condition on " + kAxis[c] +
                       " alone is not along an axis of the tilted foundation's frame, so it cannot be stated there "
                       "(a roller or symmetry condition on that face); giving all three components (x, y, z) "
                       "instead holds the face in every direction, which is other physics. Mesh the body in the "
                       "foundation's axes (contact.plane_normal a coordinate axis), where a symmetry plane's "
                       "normal stays an axis");
    out.value[k] = axis[k] * (*given.value[c] + given.gradient.row(c).dot(f.point));
    out.gradient.row(k) = axis[k] * (R * given.gradient.row(c).transpose()).transpose();
  }
  return out;
}

// The mesh is in range (checked before); in the plane's frame a node beyond ±1e15 can only come from
// contact.plane_point lying that far from the body, which the mesh check would blame on the mesh.
void require_plane_point_near_mesh(const Mesh& local_mesh, const FoundationFrame& f) {
  for (const auto& x : local_mesh.nodes)
    if (!(x.cwiseAbs().maxCoeff() <= kMaxCoordinate))
      throw InputError("contact.plane_point (" + number(f.point.x()) + ", " + number(f.point.y()) + ", " +
                       number(f.point.z()) + ") lies " + number(x.norm(), 3) +
                       " from the mesh, beyond ±1e15 in the plane's frame: give a point of the foundation plane "
                       "near the body, in the mesh's units");
}

}  // namespace

PlaneFrameProblem to_plane_frame(const Scene& scene, const Mesh& mesh) {
  const FoundationFrame& f = scene.foundation;
  const Eigen::Matrix3d& R = f.rotation;
  PlaneFrameProblem local{scene, mesh};
  local.scene.foundation = FoundationFrame();
  local.scene.user_frame = f;
  check_coordinates_in_range(mesh);  // the mesh's own coordinates, before the plane's point moves them
  for (auto& x : local.mesh.nodes) x = f.to_local_point(x);
  require_plane_point_near_mesh(local.mesh, f);
  local.scene.body_force = R * scene.body_force;
  for (auto& region : local.scene.regions)
    if (region.body_force) region.body_force = R * *region.body_force;
  for (auto& t : local.scene.tractions) {  // t(x) = v + G x, x = Rᵀx' + p
    t.value = R * (t.value + t.gradient * f.point);
    t.gradient = R * t.gradient * R.transpose();
    t.pressure += t.pressure_gradient.dot(f.point);  // p(x) = p + g·x, a scalar
    t.pressure_gradient = R * t.pressure_gradient;
  }
  for (auto& d : local.scene.displacements) d = rotate_condition(d, f);
  return local;
}

void result_to_user_frame(const FoundationFrame& frame, SolveResult& res) {
  const Eigen::Matrix3d Rt = frame.rotation.transpose();
  auto rotate_nodal = [&](Eigen::VectorXd& v) {
    for (Eigen::Index k = 0; k + 2 < v.size(); k += 3) v.segment<3>(k) = Rt * v.segment<3>(k);
  };
  rotate_nodal(res.u);
  for (auto& s : res.steps) rotate_nodal(s.u);  // λ stays in the plane's frame, as res.lambda
  res.forces.applied = Rt * res.forces.applied;
  res.forces.contact = Rt * res.forces.contact;
  res.forces.contact_at_held_nodes = Rt * res.forces.contact_at_held_nodes;
  for (auto& r : res.forces.reactions) r.force = Rt * r.force;
  res.frame = frame;
}

}  // namespace contact3d
