// Contact discretisation: 𝔹 on the paper's chessboard (row sums = cell areas, signs of the
// normal and tangential blocks) and the exact disc radii (5.3) against brute-force quadrature.
#include <gtest/gtest.h>

#include <cmath>

#include "base/errors.hpp"
#include "contact/contact_face.hpp"
#include "contact/contact_operator.hpp"
#include "contact/face_dofs.hpp"
#include "contact/foundation_frame.hpp"
#include "contact/partition.hpp"
#include "fem/dof_map.hpp"
#include "friction/friction_law.hpp"
#include "friction/slip_bound.hpp"
#include "mesh/brick_generator.hpp"

using namespace contact3d;

namespace {

struct Chessboard {
  Mesh mesh;
  DofMap dofs;
  ContactFace face;
  Partition partition;
};

Chessboard chessboard(int n) {
  Chessboard c;
  c.mesh = make_paper_brick({n});
  c.dofs = make_dof_map(c.mesh, {"clamped"});
  c.face = make_contact_face(c.mesh, {"contact"}, c.dofs);
  c.partition = make_grid_partition(c.mesh, c.face, {2 * c.face.h});
  return c;
}

}  // namespace

// A normal's direction is what counts: components near overflow or underflow give the same frame
// as [0, -1, 1] (|n|² of the raw vector would be inf or 0).
TEST(FoundationFrame, HugeAndTinyNormalsGiveTheirDirectionsFrame) {
  const FoundationFrame plain = FoundationFrame::from_plane(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, -1, 1));
  ASSERT_FALSE(plain.rotation.isIdentity(1e-3));
  for (const double size : {1e200, 1e-170, 1e-310}) {
    const FoundationFrame frame = FoundationFrame::from_plane(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, -size, size));
    EXPECT_TRUE(frame.rotation.isApprox(plain.rotation, 1e-14)) << size;
  }
  EXPECT_THROW(FoundationFrame::from_plane(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()), InputError);
}

TEST(ContactOperator, ChessboardRowsIntegrateToCellAreas) {
  const int n = 4;
  const Chessboard c = chessboard(n);
  EXPECT_DOUBLE_EQ(c.face.h, 1.0 / n);
  ASSERT_EQ(c.partition.cells.size(), std::size_t(3 * n / 2 * (n / 2)));
  const auto weights = cell_node_weights(c.face, c.partition);
  for (std::size_t i = 0; i < c.partition.cells.size(); ++i) {
    double sum = 0;
    for (const auto& [node, w] : weights[i]) sum += w;
    EXPECT_NEAR(sum, 4.0 / (n * n), 1e-14);
    EXPECT_NEAR(c.partition.cells[i].area, 4.0 / (n * n), 1e-14);
    // The chessboard cell is the 8 triangles around one (odd, odd) node: its centre node
    // carries the largest weight, (2h)²/3 ... of the 8 triangles' hats: 8 · (h²/2)/3.
    double centre = 0;
    for (const auto& [node, w] : weights[i]) centre = std::max(centre, w);
    EXPECT_NEAR(centre, 8 * (0.5 / (n * n)) / 3, 1e-14);
  }
  const ContactOperator op = make_contact_operator(c.face, c.partition, c.dofs, true);
  ASSERT_EQ(op.rows(), 3 * op.r);
  // Sums over free dofs: −area (normal) and +area (tangential) for cells away from Γu (x = 0).
  for (int i = 0; i < op.r; ++i) {
    double normal = 0, t1 = 0, t2 = 0;
    for (int j = 0; j < op.B.cols(); ++j) {
      normal += op.B.coeff(i, j);
      t1 += op.B.coeff(op.r + i, j);
      t2 += op.B.coeff(2 * op.r + i, j);
    }
    if (c.partition.cells[i].lo.x() > 0) {
      EXPECT_NEAR(normal, -c.partition.cells[i].area, 1e-14);
      EXPECT_NEAR(t1, c.partition.cells[i].area, 1e-14);
      EXPECT_NEAR(t2, c.partition.cells[i].area, 1e-14);
    } else {
      EXPECT_GT(normal, -c.partition.cells[i].area);  // clamped nodes dropped
    }
  }
  EXPECT_EQ(make_contact_operator(c.face, c.partition, c.dofs, false).rows(), op.r);
}

TEST(ContactFace, ContactNodesExcludeClampedOnes) {
  const Chessboard c = chessboard(4);
  EXPECT_EQ(c.face.nodes.size(), std::size_t(12 * 5));  // (3n+1)(n+1) minus the x = 0 row
  EXPECT_NEAR(c.face.area, 3.0, 1e-13);
}

// The slip of (5.7) is ‖w_t‖ of the whole displacement on Γc: at a face node whose tangential
// components are prescribed (the brick's end x = 0 moved 2e-5 along x, y held, z free), the prescribed
// value counts — it was taken as 0, and the coefficient at that edge was that of a node at rest.
TEST(FaceDofs, PrescribedComponentsSlip) {
  const Mesh mesh = make_paper_brick({4});
  PrescribedDisplacement moved{"clamped", {2e-5, 0.0, std::nullopt}};
  const DofMap dofs = make_dof_map(mesh, {}, {moved});
  const ContactFace face = make_contact_face(mesh, {"contact"}, dofs);
  const FaceDofs face_dofs(face, dofs, mesh.nodes.size());
  const Eigen::VectorXd at_rest = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(face_dofs.dofs.size()));
  const Eigen::VectorXd slip = face_dofs.slip(face, face_dofs.scatter(at_rest));
  int on_moved_edge = 0;
  for (std::size_t k = 0; k < face.nodes.size(); ++k) {
    const bool moved_node = mesh.nodes[face.nodes[k]].x() == 0.0;
    on_moved_edge += moved_node;
    EXPECT_DOUBLE_EQ(slip[static_cast<Eigen::Index>(k)], moved_node ? 2e-5 : 0.0);
  }
  EXPECT_EQ(on_moved_edge, 5);  // the x = 0 edge of Γc, its z free: contact nodes
}

// Heights above the plane are the initial gap d however small; only rounding (1e-12 of the mesh's
// diagonal) is put on the plane. A brick lifted 2e-8 (diagonal 3.3) was put back on it.
TEST(ContactFace, SmallLiftIsAGapAndRoundingIsNot) {
  for (const double lift : {2e-8, 1e-13}) {
    Mesh mesh = make_paper_brick({4});
    for (auto& x : mesh.nodes) x.z() += lift;
    const DofMap dofs = make_dof_map(mesh, {"clamped"});
    const ContactFace face = make_contact_face(mesh, {"contact"}, dofs);
    for (const int v : face.nodes) EXPECT_EQ(face.gap[v], lift > 1e-10 ? mesh.nodes[v].z() : 0.0) << lift;
  }
}

TEST(SlipBound, RadiiAreExactForPiecewiseLinearLaws) {
  const Chessboard c = chessboard(2);
  FrictionLaw ramp;
  ramp.kind = FrictionLaw::Kind::Ramp;
  ramp.param = 6e4;
  FrictionLaw table;
  table.kind = FrictionLaw::Kind::Table;
  table.points = {{0, 0.5}, {2e-5, 0.4}, {2e-5, 0.1}, {5e-5, 0.3}};
  // A slip field that crosses the breakpoints inside cells: φ = 4e-5 · x / 3 + 1e-5 · y.
  Eigen::VectorXd phi(c.mesh.nodes.size());
  for (std::size_t v = 0; v < c.mesh.nodes.size(); ++v)
    phi[v] = 4e-5 * c.mesh.nodes[v].x() / 3 + 1e-5 * c.mesh.nodes[v].y();
  for (const FrictionLaw& law : {ramp, table}) {
    const double g = 2e7;
    const Eigen::VectorXd radius = disc_radii(c.face, c.partition, law, g, phi);
    // Brute force: midpoint rule on a fine grid over each cell (φ is linear in x, y here).
    for (std::size_t i = 0; i < c.partition.cells.size(); ++i) {
      const auto& cell = c.partition.cells[i];
      const int m = 600;
      double sum = 0;
      for (int a = 0; a < m; ++a)
        for (int b = 0; b < m; ++b) {
          const double x = cell.lo.x() + (a + 0.5) * (cell.hi.x() - cell.lo.x()) / m;
          const double y = cell.lo.y() + (b + 0.5) * (cell.hi.y() - cell.lo.y()) / m;
          sum += law(4e-5 * x / 3 + 1e-5 * y);
        }
      EXPECT_NEAR(radius[i], g * sum / (m * m), 2e-3 * g * 0.1) << "cell " << i << " law " << law.name();
    }
  }
  FrictionLaw constant;
  constant.kind = FrictionLaw::Kind::Constant;
  constant.value = 0.3;
  const Eigen::VectorXd r = disc_radii(c.face, c.partition, constant, 2e7, phi);
  for (int i = 0; i < r.size(); ++i) EXPECT_NEAR(r[i], 0.3 * 2e7, 1e-6);
}

// φ constant on a cell at one of the law's breakpoints — a face at rest (φ ≡ 0) under a table starting
// at t = 0, a face moved by exactly t0 under the ramp — gives that value's radius F(b)·g once: it was
// clipped into both sides of b and counted twice (2·F(0)·g, 1.2e7 for 0.3·2e7).
TEST(SlipBound, ConstantSlipAtABreakpointIsCountedOnce) {
  const Chessboard c = chessboard(2);
  FrictionLaw table;
  table.kind = FrictionLaw::Kind::Table;
  table.points = {{0, 0.3}, {2e-5, 0.2}};
  FrictionLaw ramp;
  ramp.kind = FrictionLaw::Kind::Ramp;
  ramp.param = 6e4;
  for (const auto& [law, slip] : {std::pair{table, 0.0}, std::pair{ramp, ramp.t0}}) {
    const Eigen::VectorXd phi = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(c.mesh.nodes.size()), slip);
    const Eigen::VectorXd radius = disc_radii(c.face, c.partition, law, 2e7, phi);
    for (Eigen::Index i = 0; i < radius.size(); ++i) EXPECT_NEAR(radius[i], law(slip) * 2e7, 1e-6) << law.name();
  }
}

TEST(FrictionLaw, RampMatchesEquation61) {
  FrictionLaw law;
  law.kind = FrictionLaw::Kind::Ramp;
  law.param = 6e4;
  EXPECT_DOUBLE_EQ(law(0), 0.3);
  EXPECT_DOUBLE_EQ(law(1e-5), 0.3);
  EXPECT_NEAR(law(1e-5 + 1.0 / 6e4), 0.25, 1e-14);
  EXPECT_NEAR(law(1e-5 + 2.0 / 6e4), 0.2, 1e-14);
  EXPECT_DOUBLE_EQ(law(1), 0.2);
  FrictionLaw table;
  table.kind = FrictionLaw::Kind::Table;
  table.points = {{0, 0.5}, {1, 0.3}, {1, 0.1}, {2, 0.2}};
  EXPECT_DOUBLE_EQ(table(-1), 0.5);
  EXPECT_DOUBLE_EQ(table(0.5), 0.4);
  EXPECT_DOUBLE_EQ(table(1.5), 0.15);
  EXPECT_DOUBLE_EQ(table(3), 0.2);
}

// (5.1) without Q: 𝔹's dependent rows, whatever the length of its rows.
TEST(ContactOperator, DependentRowsAreFoundWhateverTheRowLengths) {
  Eigen::MatrixXd B(4, 6);
  B << 1, 2, 0, 0, 0, 0,       //
      0, 1e-7, 1e-7, 0, 0, 0,  // a short row (a small cell) that is independent
      0, 0, 0, 3, 1, 0,        //
      0, 0, 0, 0, 0, 2;
  EXPECT_TRUE(dependent_rows(B.sparseView()).empty());
  B.row(3) = 2 * B.row(0) - 5e6 * B.row(1);  // now a combination of rows 0 and 1
  const std::vector<int> bad = dependent_rows(B.sparseView());
  ASSERT_EQ(bad.size(), 1u);
  EXPECT_TRUE(bad[0] == 0 || bad[0] == 1 || bad[0] == 3) << bad[0];
  B.row(3).setZero();  // a cell with no free dof: an empty row
  EXPECT_EQ(dependent_rows(B.sparseView()), std::vector<int>{3});
}

// element_sizes_xy: a quarter annulus of triangles 0.2 across and about 1.3 along the ring (an O-ring's
// line contact) has x- and y-extents of about 0.85 both ways, which "2h" cells took as its size; scaled to
// the triangles' area they come out near sqrt(2 × 0.13). The brick's right triangles keep their extents.
TEST(ContactFace, ElementsStretchedAlongATurningDirectionTakeTheirAreasSize) {
  Mesh ring;
  const int along = 24;  // 90° in steps of 3.75°: 1.3 long at radius 20
  for (int k = 0; k <= along; ++k)
    for (const double radius : {19.9, 20.1}) {
      const double angle = M_PI / 2 * k / along;
      ring.nodes.emplace_back(radius * std::cos(angle), radius * std::sin(angle), 0.0);
    }
  std::vector<std::array<int, 3>> triangles;
  for (int k = 0; k < along; ++k) {
    triangles.push_back({2 * k, 2 * k + 2, 2 * k + 1});
    triangles.push_back({2 * k + 1, 2 * k + 2, 2 * k + 3});
  }
  const Eigen::Vector2d extents = median_extents(ring, triangles), sizes = element_sizes_xy(ring, triangles);
  EXPECT_GT(extents.minCoeff(), 0.8);
  EXPECT_NEAR(sizes.x() * sizes.y(), 2 * 0.2 * 1.309 / 2, 0.05);
  EXPECT_NEAR(sizes.x() / sizes.y(), extents.x() / extents.y(), 1e-12);

  const Mesh brick = make_paper_brick({4});
  const std::vector<int> sole = brick.triangles_of_group("contact");
  std::vector<std::array<int, 3>> sole_triangles;
  for (const int t : sole) sole_triangles.push_back(brick.triangles[static_cast<std::size_t>(t)]);
  EXPECT_EQ(element_sizes_xy(brick, sole_triangles), median_extents(brick, sole_triangles));
}
