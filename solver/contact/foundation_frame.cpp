#include "contact/foundation_frame.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "base/errors.hpp"

namespace contact3d {

FoundationFrame FoundationFrame::from_plane(const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
  // Scaled by its largest component first: |n|² of [0, -1e200, 1e200] overflows and of
  // [0, 1e-170, 1e-170] underflows, while their directions are plain.
  const double largest = normal.cwiseAbs().maxCoeff();
  if (!point.allFinite() || !normal.allFinite() || !(largest > 0))
    throw InputError(
        "contact.plane_normal must be a non-zero, finite vector (the foundation's normal, pointing "
        "towards the body)");
  FoundationFrame frame;
  frame.point = point;
  const Eigen::Vector3d n = (normal / largest).normalized();
  if (n.isApprox(Eigen::Vector3d::UnitZ(), 1e-15)) return frame;
  // The smallest rotation taking n to e_z (a half turn about e_x when n = −e_z).
  if (n.z() < -1 + 1e-15) {
    frame.rotation = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
    return frame;
  }
  frame.rotation = Eigen::Quaterniond::FromTwoVectors(n, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return frame;
}

}  // namespace contact3d
