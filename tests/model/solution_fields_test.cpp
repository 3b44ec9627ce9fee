// The fields the writers show: per-tet stress from each tet's own material (closed form for an
// affine displacement), the cell status rule, and the contact resultants with their signs.
#include <gtest/gtest.h>

#include <cmath>

#include "mesh/brick_generator.hpp"
#include "model/solution_fields.hpp"

namespace contact3d {
namespace {

// Two unit tetrahedra sharing a face (nodes 0..4).
Mesh two_tets() {
  Mesh m;
  m.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  m.tets = {{0, 1, 2, 3}, {1, 2, 3, 4}};
  m.tet_group = {1, 1};
  return m;
}

// u = ε·x (x-component only): uniaxial strain ε_xx = ε.
Eigen::VectorXd uniaxial(const Mesh& m, double eps) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(m.nodes.size()));
  for (std::size_t v = 0; v < m.nodes.size(); ++v) u[3 * v] = eps * m.nodes[v].x();
  return u;
}

TEST(TetStresses, UniaxialStrainGivesLameStressesPerMaterial) {
  const Mesh m = two_tets();
  const double eps = 1e-3, nu = 0.25;
  const TetMaterials materials(std::vector<Material>{{100.0, nu}, {300.0, nu}});
  const TetStress s = tet_stresses(m, materials, uniaxial(m, eps));
  for (std::size_t e = 0; e < 2; ++e) {
    const double E = e == 0 ? 100.0 : 300.0;
    const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    const Eigen::Matrix3d t = s.tensor(e);
    EXPECT_NEAR(t(0, 0), (lambda + 2 * mu) * eps, 1e-12 * E);
    EXPECT_NEAR(t(1, 1), lambda * eps, 1e-12 * E);
    EXPECT_NEAR(t(2, 2), lambda * eps, 1e-12 * E);
    EXPECT_NEAR(t(0, 1), 0.0, 1e-12 * E);
    EXPECT_TRUE(t.isApprox(t.transpose()));
    EXPECT_NEAR(s.von_mises[e], std::abs(t(0, 0) - t(1, 1)), 1e-12 * E);  // σ_yy = σ_zz: |σ_xx − σ_yy|
  }
}

TEST(TetStresses, ShearLandsOffTheDiagonalSymmetrically) {
  const Mesh m = two_tets();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(15);
  const double gamma = 2e-3;
  for (std::size_t v = 0; v < m.nodes.size(); ++v) u[3 * v] = gamma * m.nodes[v].y();  // u_x = γ y
  const TetStress s = tet_stresses(m, TetMaterials(Material{200.0, 0.3}), u);
  const double mu = 200.0 / (2 * 1.3);
  const Eigen::Matrix3d t = s.tensor(0);
  EXPECT_NEAR(t(0, 1), mu * gamma, 1e-12);
  EXPECT_NEAR(t(1, 0), mu * gamma, 1e-12);
  EXPECT_NEAR(t(0, 2), 0.0, 1e-12);
  EXPECT_NEAR(s.von_mises[0], std::sqrt(3.0) * mu * gamma, 1e-12);
}

TEST(LargestStrain, PrincipalStrainInAbsoluteValueAndWhere) {
  const Mesh m = two_tets();
  // Compression: the largest principal strain in absolute value is the negative one.
  StrainPeak peak = largest_strain(m, uniaxial(m, -0.2));
  EXPECT_NEAR(peak.value, 0.2, 1e-12);
  // Simple shear u_x = γ y: principal strains ±γ/2, not the engineering shear γ.
  Eigen::VectorXd u = Eigen::VectorXd::Zero(15);
  for (std::size_t v = 0; v < m.nodes.size(); ++v) u[3 * v] = 0.3 * m.nodes[v].y();
  EXPECT_NEAR(largest_strain(m, u).value, 0.15, 1e-12);
  // A small rotation about z (u = θ ẑ × x) has no linearised strain; a stretch of node 4 alone
  // strains the second tetrahedron only.
  for (std::size_t v = 0; v < m.nodes.size(); ++v) {
    u[3 * v] = -1e-3 * m.nodes[v].y();
    u[3 * v + 1] = 1e-3 * m.nodes[v].x();
    u[3 * v + 2] = 0;
  }
  EXPECT_LT(largest_strain(m, u).value, 1e-15);
  u[3 * 4 + 2] += 0.5;
  peak = largest_strain(m, u);
  EXPECT_GT(peak.value, 0.1);
  EXPECT_EQ(peak.tet, 1U);
}

// The strain that 99% of the volume stays below: the peak itself where the body is strained alike, far
// under it where one node's displacement strains only the tetrahedra around it (a local peak, which the
// large-strain warning then does not blame on the units).
TEST(LargestStrain, BulkStrainOfTheVolumeBesideTheLocalPeak) {
  const Mesh m = make_paper_brick({16});  // 20 480 tetrahedra, a node in at most a few dozen
  Eigen::VectorXd u = uniaxial(m, 0.01);
  StrainPeak peak = largest_strain(m, u);
  EXPECT_NEAR(peak.value, 0.01, 1e-12);
  EXPECT_NEAR(peak.bulk, 0.01, 1e-12);
  u[3 * 2000 + 2] += 0.5;  // one node pulled far out of the field
  peak = largest_strain(m, u);
  EXPECT_GT(peak.value, 0.1);
  EXPECT_NEAR(peak.bulk, 0.01, 1e-12);
}

TEST(CellStatus, SeparatedStickAndSlipByTheDocumentedRule) {
  // Four cells: λ_n = 0 (separated), λ_t inside the disc (stick), on the disc (slip), a tiny λ_n.
  Eigen::VectorXd lambda(12), radius(4);
  lambda << 0.0, 2.0, 2.0, 1e-9,  // λ_n
      0.0, 0.1, 0.6, 0.0,         // λ_t1
      0.0, 0.0, 0.8, 0.0;         // λ_t2
  radius << 1.0, 1.0, 1.0, 1.0;
  EXPECT_EQ(cell_status(4, lambda, radius), (std::vector<int>{kSeparated, kStick, kSlip, kSeparated}));
  // Frictionless: only normal multipliers, nothing slips.
  Eigen::VectorXd normal(2);
  normal << 1.0, 0.0;
  EXPECT_EQ(cell_status(2, normal, Eigen::VectorXd()), (std::vector<int>{kStick, kSeparated}));
}

}  // namespace
}  // namespace contact3d
