// The foundation plane of any position and orientation: a point p on it and its unit normal n
// (pointing into the body's side). The solver works in the plane's frame, x' = R (x − p), where the
// plane is z' = 0 and the body lies in z' >= 0; R is the smallest rotation taking n to e_z (the
// identity when n = e_z), so the frame's in-plane axes t1 = Rᵀe_x, t2 = Rᵀe_y are the rectangles'
// edges and the tangential multipliers' directions. Vectors map with R, points with R and p.
#pragma once

#include <Eigen/Core>

namespace contact3d {

struct FoundationFrame {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // R: global -> plane frame
  Eigen::Vector3d point = Eigen::Vector3d::Zero();         // p, global

  // Throws InputError for a zero or non-finite normal.
  static FoundationFrame from_plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal);

  bool is_identity() const { return point.isZero(0) && rotation.isIdentity(0); }
  Eigen::Vector3d normal() const { return rotation.row(2).transpose(); }  // n, global
  Eigen::Vector3d to_local(const Eigen::Vector3d& v) const { return rotation * v; }
  Eigen::Vector3d to_global(const Eigen::Vector3d& v) const { return rotation.transpose() * v; }
  Eigen::Vector3d to_local_point(const Eigen::Vector3d& x) const { return rotation * (x - point); }
  Eigen::Vector3d to_global_point(const Eigen::Vector3d& x) const { return rotation.transpose() * x + point; }
};

}  // namespace contact3d
