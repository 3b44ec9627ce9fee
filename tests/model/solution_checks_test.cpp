// The measures behind the checks on an answer (model/solution_checks.hpp): which cells count as
// pressed, how far cell centres spread across a zone, a penetration's share of the displacement, and
// the body's deformation with its rigid motion taken out.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>

#include "fem/dof_map.hpp"
#include "model/solution_checks.hpp"

namespace contact3d {
namespace {

Partition cells_at(const std::vector<Eigen::Vector2d>& centroids, const std::vector<double>& areas) {
  Partition p;
  for (std::size_t i = 0; i < centroids.size(); ++i) {
    ContactCell c;
    c.centroid = centroids[i];
    c.lo = centroids[i] - Eigen::Vector2d(0.5, 0.5);
    c.hi = centroids[i] + Eigen::Vector2d(0.5, 0.5);
    c.area = areas[i];
    p.cells.push_back(c);
  }
  return p;
}

TEST(SolutionChecks, PressedCellsCarryAThousandthOfTheLargestCellForce) {
  // Cell forces λ_n · area: 1, 1e-4 (below 1e-3 of the largest), 1.2e-3 (above: its area doubles it), 0 and a pull.
  const Partition p = cells_at({{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}}, {1, 1, 2, 1, 1});
  Eigen::VectorXd lambda(5);
  lambda << 1, 1e-4, 6e-4, 0, -5;
  EXPECT_EQ(cells_pressed(lambda, p), (std::vector<int>{0, 2}));
  EXPECT_TRUE(cells_pressed(Eigen::VectorXd::Zero(5), p).empty());  // nothing presses
  EXPECT_TRUE(cells_pressed(Eigen::VectorXd::Ones(3), p).empty());  // not this partition's multipliers
}

TEST(SolutionChecks, CentreSpreadOfARowIsZeroAcrossItAndItsVarianceAlongIt) {
  const Partition p = cells_at({{0, 2}, {1, 2}, {2, 2}, {3, 2}, {0, 5}}, {1, 1, 1, 1, 1});
  const Eigen::Matrix2d row = centroid_spread(p, {0, 1, 2, 3});
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(row);
  EXPECT_NEAR(eig.eigenvalues()[0], 0, 1e-14);
  EXPECT_NEAR(eig.eigenvalues()[1], 1.25, 1e-14);                  // centres 0..3: variance (4² − 1) / 12
  EXPECT_NEAR(std::abs(eig.eigenvectors().col(0).y()), 1, 1e-14);  // narrow across the row
  // Empty: all cells, the fifth off the row included.
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(centroid_spread(p, {})).eigenvalues()[0], 0.1);
}

TEST(SolutionChecks, PenetrationShareIsAPercentUpToTenfoldThenAFactor) {
  EXPECT_EQ(share_of_displacement(0.031), "3.1% of");
  EXPECT_EQ(share_of_displacement(0.12), "12% of");
  EXPECT_EQ(share_of_displacement(1.5), "150% of");  // not "1.5e+02% of"
  EXPECT_EQ(share_of_displacement(10), "1000% of");
  EXPECT_EQ(share_of_displacement(3.1e5), "3.1e+05 times");
  EXPECT_EQ(share_of_displacement(std::nan("")), "nan times");  // printed, not a rounded garbage percent
}

TEST(SolutionChecks, DeformationLeavesOutTheRigidMotionsItIsGiven) {
  Mesh m;
  m.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  m.tets = {{0, 1, 2, 3}};
  m.tet_group = {1};
  const DofMap dofs = make_dof_map(m, {});
  // A translation by 1 along x and a stretch of 1e-3 along z.
  Eigen::VectorXd u = Eigen::VectorXd::Zero(12);
  for (int v = 0; v < 4; ++v) u[3 * v] = 1, u[3 * v + 2] = 1e-3 * m.nodes[v].z();
  EXPECT_NEAR(largest_deformation(m, dofs, u, Eigen::MatrixXd()), std::hypot(1.0, 1e-3), 1e-12);
  Eigen::MatrixXd translations = Eigen::MatrixXd::Zero(12, 3);
  for (int v = 0; v < 4; ++v)
    for (int c = 0; c < 3; ++c) translations(3 * v + c, c) = 1;
  // The stretch less its own mean translation (u_z = 1e-3·z has mean 2.5e-4 over the four nodes).
  EXPECT_NEAR(largest_deformation(m, dofs, u, translations), 7.5e-4, 1e-12);
}

}  // namespace
}  // namespace contact3d
