// P1 elasticity: rigid motions lie in the kernel of the element stiffness, a linear
// displacement field reproduces its exact constant stress (patch test), and the assembled
// system solves a uniaxial bar exactly.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cstdlib>
#include <optional>
#include <set>

#include "base/errors.hpp"
#include "fem/assembly.hpp"
#include "fem/dof_map.hpp"
#include "fem/elasticity.hpp"
#include "fem/mesh_part.hpp"
#include "linalg/sparse_cholesky.hpp"
#include "mesh/brick_generator.hpp"
#include "test_support.hpp"

using namespace contact3d;

namespace {
TetCoords skewed_tet() {
  return {Eigen::Vector3d(0.1, 0.0, 0.2), Eigen::Vector3d(1.3, 0.2, 0.1), Eigen::Vector3d(0.3, 1.1, -0.2),
          Eigen::Vector3d(0.2, 0.4, 0.9)};
}
Eigen::Matrix<double, 12, 1> nodal(const TetCoords& x,
                                   const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& u) {
  Eigen::Matrix<double, 12, 1> v;
  for (int a = 0; a < 4; ++a) v.segment<3>(3 * a) = u(x[a]);
  return v;
}
}  // namespace

TEST(Elasticity, RigidMotionsAreInTheKernel) {
  const TetCoords x = skewed_tet();
  const Matrix12d K = element_stiffness(x, hooke_matrix({2e11, 0.3}));
  const double scale = K.norm();
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    t[c] = 1;
    EXPECT_LT((K * nodal(x, [&](const Eigen::Vector3d&) { return t; })).norm(), 1e-12 * scale);
    Eigen::Vector3d axis = Eigen::Vector3d::Zero();
    axis[c] = 1;
    EXPECT_LT((K * nodal(x, [&](const Eigen::Vector3d& p) { return Eigen::Vector3d(axis.cross(p)); })).norm(),
              1e-12 * scale);
  }
  // ... and a stretch is not.
  EXPECT_GT((K * nodal(x, [](const Eigen::Vector3d& p) { return Eigen::Vector3d(p.x(), 0, 0); })).norm(), 1e-3 * scale);
  // Symmetric, six zero eigenvalues, the rest positive.
  EXPECT_LT((K - K.transpose()).norm(), 1e-12 * scale);
  Eigen::SelfAdjointEigenSolver<Matrix12d> eig(K);
  for (int k = 0; k < 6; ++k) EXPECT_LT(std::abs(eig.eigenvalues()[k]), 1e-10 * scale);
  for (int k = 6; k < 12; ++k) EXPECT_GT(eig.eigenvalues()[k], 1e-6 * scale);
}

TEST(Elasticity, LinearFieldGivesItsExactStrain) {
  const TetCoords x = skewed_tet();
  Eigen::Matrix3d G;
  G << 1e-3, 2e-3, -1e-3, 0.5e-3, -2e-3, 3e-3, 1e-3, 0, 4e-3;
  const auto u = nodal(x, [&](const Eigen::Vector3d& p) { return Eigen::Vector3d(G * p); });
  const Eigen::Matrix<double, 6, 1> eps = strain_matrix(x) * u;
  EXPECT_NEAR(eps[0], G(0, 0), 1e-14);
  EXPECT_NEAR(eps[1], G(1, 1), 1e-14);
  EXPECT_NEAR(eps[2], G(2, 2), 1e-14);
  EXPECT_NEAR(eps[3], G(1, 2) + G(2, 1), 1e-14);
  EXPECT_NEAR(eps[4], G(0, 2) + G(2, 0), 1e-14);
  EXPECT_NEAR(eps[5], G(0, 1) + G(1, 0), 1e-14);
}

// A dof map with every node free except `fixed` nodes, whose three components are prescribed
// by `value(node)`.
template <class Value>
DofMap dofs_fixing(const Mesh& mesh, const std::set<int>& fixed, Value value) {
  DofMap dofs;
  dofs.n_nodes = static_cast<int>(mesh.nodes.size());
  dofs.fixed.assign(dofs.n_nodes, 0);
  dofs.used.assign(dofs.n_nodes, 1);
  dofs.prescribed.assign(3 * dofs.n_nodes, 0.0);
  dofs.fixed_by.assign(3 * dofs.n_nodes, -1);
  dofs.conditions = {"test"};
  dofs.free_index.assign(3 * dofs.n_nodes, -1);
  for (int v = 0; v < dofs.n_nodes; ++v) {
    const bool fix = fixed.count(v) > 0;
    const Eigen::Vector3d g = value(v);
    for (int c = 0; c < 3; ++c) {
      if (fix) {
        dofs.prescribed[3 * v + c] = g[c];
        dofs.fixed_by[3 * v + c] = 0;
      } else {
        dofs.free_index[3 * v + c] = dofs.n_free++;
      }
    }
    if (fix) dofs.fixed[v] = 7;
  }
  return dofs;
}

// Patch test on the paper's brick mesh: prescribe an exact linear field on every boundary node;
// the lift −K_fc·u_c and the free solve reproduce it inside, interior nodes carry no residual and
// the boundary's reactions (a homogeneous stress) sum to zero.
TEST(Assembly, PatchTestLinearFieldIsReproducedInside) {
  const Mesh mesh = make_paper_brick({2});
  std::set<int> boundary;
  for (const auto& f : boundary_faces(mesh)) boundary.insert(f.begin(), f.end());
  Eigen::Matrix3d G;
  G << 1e-3, 2e-3, -1e-3, 0.5e-3, -2e-3, 3e-3, 1e-3, 0, 4e-3;
  const DofMap dofs = dofs_fixing(mesh, boundary, [&](int v) { return Eigen::Vector3d(G * mesh.nodes[v]); });
  ASSERT_GT(dofs.n_free, 0);
  const Material mat{1e9, 0.3};
  const SparseCholesky K(assemble_stiffness(mesh, dofs, mat));
  const Eigen::VectorXd u = expand_to_nodes(dofs, K.solve(assemble_lift(mesh, dofs, mat)));
  for (int v = 0; v < dofs.n_nodes; ++v)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(u[3 * v + c], (G * mesh.nodes[v])[c], 1e-12);
  const Eigen::VectorXd r = internal_minus_external(mesh, mat, {}, Eigen::Vector3d::Zero(), u);
  const auto reactions = reaction_forces(dofs, r);
  ASSERT_EQ(reactions.size(), 1u);
  EXPECT_LT(reactions[0].force.norm(), 1e-6 * r.cwiseAbs().maxCoeff());  // a homogeneous stress is self-balanced
  for (int v = 0; v < dofs.n_nodes; ++v)                                 // interior nodes carry no residual
    if (!boundary.count(v)) { EXPECT_LT(r.segment<3>(3 * v).norm(), 1e-9 * r.cwiseAbs().maxCoeff()); }
}

TEST(Assembly, TractionLoadSumsToForce) {
  const Mesh mesh = make_paper_brick({2});
  const DofMap all = dofs_fixing(mesh, {}, [](int) { return Eigen::Vector3d::Zero(); });
  Traction top;
  top.group = "load_top";
  top.value = Eigen::Vector3d(0, 0, -3e7);
  const Eigen::VectorXd f = assemble_load(mesh, all, {top}, Eigen::Vector3d(0, 0, -10));
  double fz = 0;
  for (int v = 0; v < all.n_nodes; ++v) fz += f[3 * v + 2];
  EXPECT_NEAR(fz, -3e7 * 3.0 - 10 * 3.0, 1e-6);  // top face area 3 m², volume 3 m³
}

// Sum over the nodes of a nodal load vector (3 per node).
Eigen::Vector3d total_force(const Eigen::VectorXd& f) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (Eigen::Index v = 0; v < f.size() / 3; ++v) sum += f.segment<3>(3 * v);
  return sum;
}

// A pressure pushes along the inward normal of each face, whatever the triangles' orientation; an
// affine traction is integrated exactly (∫ G x dS = G x̄ |S|, and the first moment too).
TEST(Assembly, PressureAndAffineTractionsIntegrateExactly) {
  const Mesh mesh = make_paper_brick({2});
  const DofMap all = dofs_fixing(mesh, {}, [](int) { return Eigen::Vector3d::Zero(); });
  Traction top;  // z = 1, area 3, centroid (1.5, 0.5, 1)
  top.group = "load_top";
  top.pressure = 2e6;
  Eigen::Vector3d f = total_force(assemble_load(mesh, all, {top}, Eigen::Vector3d::Zero()));
  EXPECT_NEAR(f.z(), -2e6 * 3.0, 1e-6);
  EXPECT_NEAR(f.head<2>().norm(), 0.0, 1e-6);
  Traction end;  // x = 3, area 1: outward normal +x, so the pressure pushes along −x
  end.group = "load_end";
  end.pressure = 5.0;
  f = total_force(assemble_load(mesh, all, {end}, Eigen::Vector3d::Zero()));
  EXPECT_NEAR(f.x(), -5.0, 1e-12);
  Traction torsion;  // τ (−y, x, 0) on the top face
  torsion.group = "load_top";
  torsion.gradient << 0, -7, 0, 7, 0, 0, 0, 0, 0;
  const Eigen::VectorXd load = assemble_load(mesh, all, {torsion}, Eigen::Vector3d::Zero());
  f = total_force(load);
  EXPECT_NEAR(f.x(), -7 * 0.5 * 3.0, 1e-9);
  EXPECT_NEAR(f.y(), 7 * 1.5 * 3.0, 1e-9);
  // The moment about the z axis: ∫ x t_y − y t_x = 7 ∫ (x² + y²) dS over [0,3]×[0,1] = 7 (9 + 1).
  double mz = 0;
  for (int v = 0; v < all.n_nodes; ++v) mz += mesh.nodes[v].x() * load[3 * v + 1] - mesh.nodes[v].y() * load[3 * v];
  EXPECT_NEAR(mz, 7 * (9.0 + 1.0), 1e-9);
  Traction wrong;
  wrong.group = "no_such_group";
  wrong.pressure = 1;
  EXPECT_THROW(assemble_load(mesh, all, {wrong}, Eigen::Vector3d::Zero()), InputError);
}

// A pressure that varies in space, p(x) = p₀ + g·x (a hydrostatic load), along the inward normal:
// its resultant is ∫p dS and its moment ∫x × (−p n) dS, both exact for P1 shape functions.
TEST(Assembly, AffinePressureIntegratesExactly) {
  const Mesh mesh = make_paper_brick({2});
  const DofMap all = dofs_fixing(mesh, {}, [](int) { return Eigen::Vector3d::Zero(); });
  Traction end;  // x = 3, y ∈ [0,1], z ∈ [0,1]; outward normal +x
  end.group = "load_end";
  end.pressure = 4e5;
  end.pressure_gradient = Eigen::Vector3d(1e3, 2e5, -6e5);  // the x term is the constant 3e3 on the face
  const Eigen::VectorXd load = assemble_load(mesh, all, {end}, Eigen::Vector3d::Zero());
  const double mean_p = 4e5 + 3e3 + 2e5 * 0.5 - 6e5 * 0.5;
  const Eigen::Vector3d f = total_force(load);
  EXPECT_NEAR(f.x(), -mean_p, 1e-6);
  EXPECT_NEAR(f.tail<2>().norm(), 0.0, 1e-6);
  // Moment about the y axis of the force −p along x at height z: ∫ z·(−p) dS, with ∫z = 1/2, ∫z² = 1/3,
  // ∫yz = 1/4 over the unit square.
  double my = 0;
  for (int v = 0; v < all.n_nodes; ++v) my += mesh.nodes[v].z() * load[3 * v];
  EXPECT_NEAR(my, -((4e5 + 3e3) * 0.5 + 2e5 * 0.25 - 6e5 / 3.0), 1e-6);
  EXPECT_TRUE(end.has_pressure());
  end.pressure = 0;  // a gradient alone is a pressure too
  EXPECT_NEAR(total_force(assemble_load(mesh, all, {end}, Eigen::Vector3d::Zero())).x(), -(mean_p - 4e5), 1e-6);
}

// Clamped brick under load: the clamp's reaction balances the applied load.
// A prescribed displacement that varies in space: each node of the group gets value + gradient·x
// on the given components; two conditions that give a shared node the same field in different forms
// agree up to rounding, different fields are refused.
TEST(DofMap, AffinePrescribedDisplacementAtEachNode) {
  const Mesh mesh = make_paper_brick({2});
  PrescribedDisplacement tilt{"load_end", {0.0, std::nullopt, 1e-4}};  // x = 3 face
  tilt.gradient << 0, 0, 2e-5, 0, 0, 0, -1e-5, 3e-5, 0;
  const DofMap dofs = make_dof_map(mesh, {"clamped"}, {tilt});
  int checked = 0;
  for (int t : mesh.triangles_of_group("load_end"))
    for (int v : mesh.triangles[t]) {
      const Eigen::Vector3d& x = mesh.nodes[v];
      EXPECT_DOUBLE_EQ(dofs.prescribed[3 * v], 2e-5 * x.z());
      EXPECT_DOUBLE_EQ(dofs.prescribed[3 * v + 2], 1e-4 - 1e-5 * x.x() + 3e-5 * x.y());
      EXPECT_GE(dofs.dof(v, 1), 0);  // y is free
      ++checked;
    }
  EXPECT_GT(checked, 0);
  // The top face (z = 1) shares the edge x = 3, z = 1 with the end: u_z there is 1e-4 − 3e-5 + 3e-5·y.
  PrescribedDisplacement same{"load_top", {std::nullopt, std::nullopt, 0.7e-4 + 1e-20}};
  same.gradient.row(2) = Eigen::RowVector3d(0, 3e-5, 0);
  PrescribedDisplacement lifted = same;
  lifted.value[2] = 0.7e-4 + 1e-9;
  EXPECT_NO_THROW(make_dof_map(mesh, {}, {tilt, same}));
  EXPECT_THROW(make_dof_map(mesh, {}, {tilt, lifted}), InputError);
}

TEST(Assembly, ReactionBalancesTheLoad) {
  const Mesh mesh = make_paper_brick({2});
  const DofMap dofs = make_dof_map(mesh, {"clamped"});
  const Material mat{2e11, 0.3};
  Traction end;
  end.group = "load_end";
  end.value = Eigen::Vector3d(1e7, 0, 2e7);
  const Eigen::Vector3d body(0, 0, -7e4);
  const SparseCholesky K(assemble_stiffness(mesh, dofs, mat));
  const Eigen::VectorXd u = expand_to_nodes(dofs, K.solve(assemble_load(mesh, dofs, {end}, body)));
  const auto reactions = reaction_forces(dofs, internal_minus_external(mesh, mat, {end}, body, u));
  ASSERT_EQ(reactions.size(), 1u);
  EXPECT_EQ(reactions[0].condition, "boundary.clamped 'clamped'");
  const Eigen::Vector3d applied = Eigen::Vector3d(1e7, 0, 2e7) + body * 3.0;
  EXPECT_LT((reactions[0].force + applied).norm(), 1e-6 * applied.norm());
}

// Per-component conditions: the dof map fixes only the named components, conflicting values are
// refused, and the node-ordered fast assembly equals the triplet assembly with partly free nodes
// and with one material per tetrahedron.
TEST(Assembly, PerComponentConditionsAndMaterials) {
  const Mesh mesh = make_paper_brick({2});
  PrescribedDisplacement roller{"contact", {std::nullopt, std::nullopt, 0.0}};
  PrescribedDisplacement push{"load_end", {-1e-3, std::nullopt, std::nullopt}};
  const DofMap dofs = make_dof_map(mesh, {"clamped"}, {roller, push});
  int partly = 0;
  for (int v = 0; v < dofs.n_nodes; ++v) partly += dofs.fixed[v] != 0 && dofs.fixed[v] != 7;
  EXPECT_GT(partly, 0);
  EXPECT_TRUE(dofs.has_nonzero_prescribed());
  EXPECT_EQ(dofs.conditions.size(), 3u);
  std::vector<Material> per_tet(mesh.tets.size(), Material{2e11, 0.3});
  for (std::size_t e = 0; e < per_tet.size(); e += 3) per_tet[e] = Material{7e10, 0.33};
  const TetMaterials mixed(per_tet);
  const Eigen::SparseMatrix<double> fast = assemble_stiffness(mesh, dofs, mixed);
  const Eigen::SparseMatrix<double> ref = assemble_stiffness_triplets(mesh, dofs, mixed);
  ASSERT_EQ(fast.rows(), dofs.n_free);
  EXPECT_LT((fast - ref).norm(), 1e-13 * ref.norm());
  // The columns of three node ranges (the ranks' shares in the distributed backend) are K's, from
  // the whole mesh and from the part of it a rank receives (the tets around its nodes).
  const int cut1 = dofs.n_nodes / 3, cut2 = dofs.n_nodes / 2;
  for (const auto& [lo, hi] : {std::pair{0, cut1}, std::pair{cut1, cut2}, std::pair{cut2, dofs.n_nodes}}) {
    const int first = first_free_dof(dofs, lo);
    const Eigen::SparseMatrix<double> expected = ref.middleCols(first, first_free_dof(dofs, hi) - first);
    const Eigen::SparseMatrix<double> block = assemble_stiffness_columns(mesh, dofs, mixed, lo, hi);
    EXPECT_LT((block - expected).norm(), 1e-13 * ref.norm());
    const MeshPart part = cut_mesh_part(mesh, dofs, mixed, lo, hi);
    EXPECT_LT(part.mesh.tets.size(), mesh.tets.size());
    const Eigen::SparseMatrix<double> from_part =
        assemble_stiffness_columns(part.mesh, part.dofs, TetMaterials(part.materials), part.first_node, part.last_node);
    ASSERT_EQ(from_part.cols(), expected.cols());
    EXPECT_LT((from_part - expected).norm(), 1e-13 * ref.norm());
  }
  // The ranks' node ranges cover the mesh in order, with about n_free / parts dofs each.
  for (int parts : {1, 2, 3, 7}) {
    const std::vector<int> split = split_nodes_by_dofs(dofs, parts);
    ASSERT_EQ(split.size(), static_cast<std::size_t>(parts) + 1);
    EXPECT_EQ(split.front(), 0);
    EXPECT_EQ(split.back(), dofs.n_nodes);
    for (int r = 0; r < parts; ++r) {
      EXPECT_LE(split[r], split[r + 1]);
      const int owned = first_free_dof(dofs, split[r + 1]) - first_free_dof(dofs, split[r]);
      EXPECT_LE(std::abs(owned - dofs.n_free / parts), 4) << parts << " parts, part " << r;  // a node has <= 3 dofs
    }
  }
  // K·w element by element (what rank 0 uses once it has freed K) is the assembled product.
  const Eigen::VectorXd w = Eigen::VectorXd::LinSpaced(dofs.n_free, -1.0, 2.0).array().sin();
  const Eigen::VectorXd Kw = ref * w;
  EXPECT_LT((apply_stiffness(mesh, dofs, mixed, w) - Kw).norm(), 1e-13 * Kw.norm());
  // K's diagonal at a few free dofs (the pins' springs on the distributed route) from the elements at their nodes.
  const std::vector<int> some = {0, 1, dofs.n_free / 2, dofs.n_free - 1};
  const std::vector<double> diagonal = stiffness_diagonal_at(mesh, dofs, mixed, some);
  ASSERT_EQ(diagonal.size(), some.size());
  for (std::size_t k = 0; k < some.size(); ++k)
    EXPECT_NEAR(diagonal[k], ref.coeff(some[k], some[k]), 1e-13 * ref.coeff(some[k], some[k])) << some[k];
  PrescribedDisplacement clash{"load_end", {+1e-3, std::nullopt, std::nullopt}};
  try {
    make_dof_map(mesh, {"clamped"}, {push, clash});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("prescribed twice"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("load_end"), std::string::npos) << e.what();
  }
}

namespace {

// The n = 2 brick (clamped at x = 0) with a copy moved by `shift` whose nodes that fall on the first
// brick's are merged into them; the copy keeps no boundary triangles (nothing prescribed on it).
Mesh brick_with_joined_copy(const Eigen::Vector3d& shift) {
  const Mesh brick = make_paper_brick({2});
  Mesh mesh = contact3d::testing::with_moved_copy(brick, shift);
  mesh.triangles.resize(brick.triangles.size());
  mesh.triangle_tags.resize(brick.triangles.size());
  mesh.triangle_group.resize(brick.triangles.size());
  const int n = static_cast<int>(brick.nodes.size());
  std::vector<int> merged(mesh.nodes.size());
  for (int v = 0; v < static_cast<int>(mesh.nodes.size()); ++v) {
    merged[static_cast<std::size_t>(v)] = v;
    if (v < n) continue;
    for (int w = 0; w < n; ++w)
      if ((mesh.nodes[static_cast<std::size_t>(v)] - brick.nodes[static_cast<std::size_t>(w)]).norm() < 1e-12)
        merged[static_cast<std::size_t>(v)] = w;
  }
  for (auto& tet : mesh.tets)
    for (int& v : tet) v = merged[static_cast<std::size_t>(v)];
  return mesh;
}

}  // namespace

// Tetrahedra that share a face move as one rigid block when K's energy is zero; a block joined to the
// rest only along a line of edges (a hinge) or at one node (a ball joint) turns about it freely, K
// singular along that motion: named before anything is factorized. Joined through a face, or with the
// turn prescribed, nothing is found; so for the brick alone and for two disconnected parts.
TEST(DofMap, BlocksJoinedOnlyAlongAnEdgeOrAtANodeAreMechanisms) {
  const Mesh brick = make_paper_brick({2});
  EXPECT_EQ(find_mechanism(brick, make_dof_map(brick, {"clamped"}), body_parts(brick)), "");

  const Mesh hinged = brick_with_joined_copy({3, 0, 1});  // shares the edge x = 3, z = 1
  const std::string hinge = find_mechanism(hinged, make_dof_map(hinged, {"clamped"}), body_parts(hinged));
  EXPECT_NE(hinge.find("a hinge"), std::string::npos) << hinge;
  EXPECT_NE(hinge.find("(3, 0, 1) to (3, 1, 1)"), std::string::npos) << hinge;

  const Mesh ball = brick_with_joined_copy({3, 1, 1});  // shares the node (3, 1, 1)
  const std::string joint = find_mechanism(ball, make_dof_map(ball, {"clamped"}), body_parts(ball));
  EXPECT_NE(joint.find("only at the node (3, 1, 1)"), std::string::npos) << joint;

  const Mesh glued = brick_with_joined_copy({3, 0, 0});  // shares the face x = 3
  EXPECT_EQ(find_mechanism(glued, make_dof_map(glued, {"clamped"}), body_parts(glued)), "");
  // The hinge's turn prescribed: every node of the copy's top held.
  DofMap held = make_dof_map(hinged, {"clamped"});
  for (int v = static_cast<int>(brick.nodes.size()); v < held.n_nodes; ++v)
    if (held.used[v] && std::abs(hinged.nodes[v].z() - 2) < 1e-12) held.fixed[v] |= 7;
  EXPECT_EQ(find_mechanism(hinged, held, body_parts(hinged)), "");
  // Two parts sharing no node are parts, not a mechanism (free_rigid_motions names them).
  const Mesh apart = brick_with_joined_copy({5, 0, 0});
  EXPECT_EQ(find_mechanism(apart, make_dof_map(apart, {"clamped"}), body_parts(apart)), "");
}

// The rigid part of the prescribed values: none for clamps and rollers at 0; a prescribed translation
// or rotation of a face exactly; only the prescribed components' share where they leave motions free.
TEST(DofMapRigidMotions, PrescribedRigidMotionFitsThePrescribedValues) {
  const Mesh mesh = make_paper_brick({2});
  const auto at = [&](const Eigen::VectorXd& field, int v) { return Eigen::Vector3d(field.segment<3>(3 * v)); };
  PrescribedDisplacement roller{"contact", {std::nullopt, std::nullopt, 0.0}};
  EXPECT_EQ(prescribed_rigid_motion(mesh, make_dof_map(mesh, {"clamped"}, {roller})).norm(), 0.0);
  // The clamped face pushed down by δ: that translation at every node.
  const double delta = 2e-5;
  const DofMap pushed = make_dof_map(mesh, {}, {PrescribedDisplacement{"clamped", {0.0, 0.0, -delta}}});
  const Eigen::VectorXd translation = prescribed_rigid_motion(mesh, pushed);
  for (int v = 0; v < static_cast<int>(mesh.nodes.size()); ++v)
    EXPECT_LT((at(translation, v) - Eigen::Vector3d(0, 0, -delta)).norm(), 1e-12 * delta) << v;
  // u_z = −δ alone on the bottom: the translation along z, nothing along the motions left free.
  const DofMap lowered =
      make_dof_map(mesh, {}, {PrescribedDisplacement{"contact", {std::nullopt, std::nullopt, -delta}}});
  const Eigen::VectorXd along_z = prescribed_rigid_motion(mesh, lowered);
  for (int v = 0; v < static_cast<int>(mesh.nodes.size()); ++v)
    EXPECT_LT((at(along_z, v) - Eigen::Vector3d(0, 0, -delta)).norm(), 1e-12 * delta) << v;
  // The bottom (z = 0) turned about the y axis through the origin by a small angle θ: (0, 0, −θ x) at
  // its nodes; the fit is that rotation, (θ z, 0, −θ x) at every node.
  const double theta = 1e-4;
  DofMap turned = make_dof_map(mesh, {}, {PrescribedDisplacement{"contact", {0.0, 0.0, 0.0}}});
  for (int v = 0; v < static_cast<int>(mesh.nodes.size()); ++v)
    if (turned.fixed[v] & 4) turned.prescribed[static_cast<std::size_t>(3 * v + 2)] = -theta * mesh.nodes[v].x();
  const Eigen::VectorXd rotation = prescribed_rigid_motion(mesh, turned);
  for (int v = 0; v < static_cast<int>(mesh.nodes.size()); ++v) {
    const Eigen::Vector3d& x = mesh.nodes[v];
    EXPECT_LT((at(rotation, v) - Eigen::Vector3d(theta * x.z(), 0, -theta * x.x())).norm(), 1e-9 * theta) << v;
  }
}

// Free rigid motions are found and named before any factorization.
TEST(Assembly, FreeRigidMotionsAreNamed) {
  const Mesh mesh = make_paper_brick({2});
  auto message = [&](const std::vector<std::string>& clamped, const std::vector<PrescribedDisplacement>& d) {
    try {
      require_rigid_motions_fixed(mesh, make_dof_map(mesh, clamped, d));
      return std::string();
    } catch (const InputError& e) { return std::string(e.what()); }
  };
  EXPECT_EQ(message({"clamped"}, {}), "");
  // Rollers on z = 0 (u_z) and x = 0 (u_x): the body can still slide along y.
  const PrescribedDisplacement floor{"contact", {std::nullopt, std::nullopt, 0.0}};
  const PrescribedDisplacement wall{"clamped", {0.0, std::nullopt, std::nullopt}};
  const std::string slide = message({}, {floor, wall});
  EXPECT_NE(slide.find("translation along (0, 1, 0)"), std::string::npos) << slide;
  // u_y on x = 0 with u_x, u_z on z = 0 hold every rigid motion.
  const PrescribedDisplacement floor_xz{"contact", {0.0, std::nullopt, 0.0}};
  const PrescribedDisplacement wall_y{"clamped", {std::nullopt, 0.0, std::nullopt}};
  EXPECT_EQ(message({}, {floor_xz, wall_y}), "");
  // All components fixed on the edge x = 0, z = 0 only: the body turns about that edge.
  std::set<int> edge;
  for (int v = 0; v < static_cast<int>(mesh.nodes.size()); ++v)
    if (mesh.nodes[v].x() == 0 && mesh.nodes[v].z() == 0) edge.insert(v);
  try {
    require_rigid_motions_fixed(mesh, dofs_fixing(mesh, edge, [](int) { return Eigen::Vector3d::Zero(); }));
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("rotation about the axis along (0, "), std::string::npos) << what;
    EXPECT_NE(what.find("through (0, 0.5, 0)"), std::string::npos) << what;
  }
}

// Two copies of the n = 2 brick, the second moved 5 m along x: two parts sharing no node. Each part's
// free rigid motions are its own: the first clamped (none), the second held only by u_z on its
// bottom (its slides and its turn about z).
TEST(DofMap, EachDisconnectedPartHasItsOwnFreeMotions) {
  const Mesh copy = make_paper_brick({2});
  Mesh mesh = contact3d::testing::with_moved_copy(copy, {5, 0, 0});
  // The boundary triangles of the first copy only: its clamped group and bottom.
  mesh.triangles.resize(copy.triangles.size());
  mesh.triangle_tags.resize(copy.triangles.size());
  mesh.triangle_group.resize(copy.triangles.size());
  const int offset = static_cast<int>(copy.nodes.size());
  const BodyParts parts = body_parts(mesh);
  ASSERT_EQ(parts.count(), 2);
  EXPECT_EQ(parts.tets[0], static_cast<int>(copy.tets.size()));
  EXPECT_EQ(parts.tets[1], static_cast<int>(copy.tets.size()));
  EXPECT_EQ(parts.of_node[0], 0);
  EXPECT_EQ(parts.of_node[static_cast<std::size_t>(offset)], 1);
  EXPECT_EQ(body_parts(copy).count(), 1);

  // The clamped group and the bottom are the first copy's triangles: the second part touches none.
  const DofMap dofs = make_dof_map(mesh, {"clamped"});
  EXPECT_EQ(free_rigid_motions(mesh, dofs).count(), 0);  // the whole body's check sees nothing free
  EXPECT_EQ(free_rigid_motions(mesh, dofs, parts, 0).count(), 0);
  EXPECT_EQ(free_rigid_motions(mesh, dofs, parts, 1).count(), 6);
  // Its bottom on rollers (u_z) as well: three motions left, every one without a normal part.
  std::set<int> bottom;
  for (int v = offset; v < static_cast<int>(mesh.nodes.size()); ++v)
    if (mesh.nodes[v].z() == 0) bottom.insert(v);
  DofMap rollers = make_dof_map(mesh, {"clamped"});
  for (int v : bottom) rollers.fixed[v] |= 4;
  const FreeRigidMotions left = free_rigid_motions(mesh, rollers, parts, 1);
  ASSERT_EQ(left.count(), 3);
  for (int j = 0; j < 3; ++j) {
    EXPECT_LT(std::abs(left.motions(2, j)), 1e-9) << j;           // no lift
    EXPECT_LT(left.motions.block(3, j, 2, 1).norm(), 1e-9) << j;  // no tilt
  }
  // About its own centroid: the first copy's, moved.
  const Eigen::Vector3d own = free_rigid_motions(copy, make_dof_map(copy, {})).centre + Eigen::Vector3d(5, 0, 0);
  EXPECT_LT((left.centre - own).norm(), 1e-12);
}

TEST(Assembly, RejectsInvertedTets) {
  Mesh mesh = make_paper_brick({1});
  std::swap(mesh.tets[2][0], mesh.tets[2][1]);
  try {
    check_tet_orientation(mesh);
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("inverted"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find(std::to_string(mesh.tet_tags[2])), std::string::npos);
  }
}

TEST(Assembly, NodeOrderedAssemblyEqualsTripletAssembly) {
  for (int n : {1, 3}) {
    const Mesh mesh = make_paper_brick({n});
    const DofMap dofs = make_dof_map(mesh, {"clamped"});
    const Material mat{2e11, 0.3};
    const Eigen::SparseMatrix<double> fast = assemble_stiffness(mesh, dofs, mat);
    const Eigen::SparseMatrix<double> ref = assemble_stiffness_triplets(mesh, dofs, mat);
    ASSERT_EQ(fast.rows(), ref.rows());
    EXPECT_LT((fast - ref).norm(), 1e-13 * ref.norm()) << "n = " << n;
    EXPECT_LT((Eigen::SparseMatrix<double>(fast.transpose()) - fast).norm(), 1e-13 * ref.norm());
  }
}

// The near-null space: orthonormal, annihilated by the unconstrained K to rounding, and on a
// clamped body the same motions restricted to the free dofs (K·R then vanishes away from Γu).
TEST(DofMap, RigidBodyModesSpanTheKernelOfTheFreeBody) {
  const Mesh mesh = make_paper_brick({3});
  const Material mat{2e11, 0.3};
  const DofMap all = make_dof_map(mesh, {});
  const Eigen::MatrixXd R = rigid_body_modes(mesh, all);
  ASSERT_EQ(R.cols(), 6);
  EXPECT_LT((R.transpose() * R - Eigen::MatrixXd::Identity(6, 6)).norm(), 1e-12);
  const Eigen::SparseMatrix<double> K = assemble_stiffness(mesh, all, mat);
  const double k_norm = Eigen::MatrixXd(K).norm();
  EXPECT_LT((K * R).norm(), 1e-12 * k_norm);
  // The six modes are independent: K has no other null vector, so its seventh-smallest eigenvalue
  // is far from zero (the modes are the whole kernel).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd(K), Eigen::EigenvaluesOnly);
  EXPECT_GT(eig.eigenvalues()[6], 1e-6 * eig.eigenvalues().maxCoeff());

  const DofMap clamped = make_dof_map(mesh, {"clamped"});
  const Eigen::MatrixXd Rc = rigid_body_modes(mesh, clamped);
  Eigen::MatrixXd restricted(clamped.n_free, 6);
  for (int v = 0; v < clamped.n_nodes; ++v)
    for (int c = 0; c < 3; ++c)
      if (const int d = clamped.dof(v, c); d >= 0) restricted.row(d) = R.row(all.dof(v, c));
  // Same span: projecting the restricted motions onto Rc's columns loses nothing.
  EXPECT_LT((restricted - Rc * (Rc.transpose() * restricted)).norm(), 1e-12 * restricted.norm());
  const Eigen::VectorXd residual = (assemble_stiffness(mesh, clamped, mat) * Rc).rowwise().norm();
  int quiet_rows = 0;  // rows of nodes whose tets touch no clamped node
  std::vector<char> near_clamp(mesh.nodes.size(), 0);
  for (const auto& t : mesh.tets) {
    bool touches = false;
    for (int v : t) touches = touches || clamped.fixed[v] != 0;
    if (touches)
      for (int v : t) near_clamp[v] = 1;
  }
  for (int v = 0; v < clamped.n_nodes; ++v)
    for (int c = 0; c < 3; ++c)
      if (const int d = clamped.dof(v, c); d >= 0 && !near_clamp[v]) {
        EXPECT_LT(residual[d], 1e-12 * k_norm) << "node " << v;
        ++quiet_rows;
      }
  EXPECT_GT(quiet_rows, clamped.n_free / 2);
}
