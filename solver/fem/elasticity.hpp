// P1 linear elasticity on one tetrahedron: the isotropic Hooke law, the strain-displacement
// matrix and the 12x12 element stiffness K_e = |T| Bᵀ D B (the bilinear form a(u,v) of §2).
#pragma once

#include <array>
#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace contact3d {

struct Material {
  double young = 1.0;    // E, Pa
  double poisson = 0.0;  // ν
};

// The material of every tetrahedron: one for the whole body, or one per tetrahedron (several
// materials, one per volume group, as Abaqus sections).
class TetMaterials {
 public:
  TetMaterials(const Material& whole_body) : single_(whole_body) {}  // NOLINT: one material converts implicitly
  explicit TetMaterials(std::vector<Material> per_tet) : per_tet_(std::move(per_tet)) {}
  const Material& operator[](std::size_t tet) const { return per_tet_.empty() ? single_ : per_tet_[tet]; }

 private:
  Material single_;
  std::vector<Material> per_tet_;
};

// The body force (N/m³, material.body_force): one for the whole body, or one per tetrahedron where
// material regions weigh differently (steel on rubber under gravity).
class BodyForce {
 public:
  template <class Derived>
  BodyForce(const Eigen::MatrixBase<Derived>& whole_body) : single_(whole_body) {}  // NOLINT: converts implicitly
  explicit BodyForce(std::vector<Eigen::Vector3d> per_tet) : per_tet_(std::move(per_tet)) {}
  const Eigen::Vector3d& operator[](std::size_t tet) const { return per_tet_.empty() ? single_ : per_tet_[tet]; }
  bool is_zero() const {
    if (per_tet_.empty()) return single_.isZero(0);
    for (const auto& b : per_tet_)
      if (!b.isZero(0)) return false;
    return true;
  }

 private:
  Eigen::Vector3d single_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> per_tet_;
};

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix6x12d = Eigen::Matrix<double, 6, 12>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;
using TetCoords = std::array<Eigen::Vector3d, 4>;

// Voigt order (xx, yy, zz, yz, xz, xy) with engineering shear strains.
Matrix6d hooke_matrix(const Material& m);
double tet_volume(const TetCoords& x);  // signed
// Strain of the P1 field with nodal displacements u (12: node-major xyz).
Matrix6x12d strain_matrix(const TetCoords& x);
Matrix12d element_stiffness(const TetCoords& x, const Matrix6d& D);

}  // namespace contact3d
