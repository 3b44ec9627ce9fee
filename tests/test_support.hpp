// Shared fixtures of the unit tests: the paper's scene as TOML text, small random QPs of the form
// (5.5) with both constraint kinds (also as matrix-free ones), a grid Laplacian to factor, and a
// mesh with moved copies of itself (a mesh of several parts).
#pragma once

#include <unistd.h>

#include <array>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include "base/errors.hpp"
#include "linalg/dense_cholesky.hpp"
#include "linalg/dual_operator.hpp"
#include "mesh/mesh.hpp"
#include "qp/box_disc_qp.hpp"

namespace contact3d::testing {

// An empty folder of its own under the system's temporary directory: "contact3d_<name>_<pid>".
inline std::filesystem::path fresh_temp_folder(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("contact3d_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// stiffness · (7-point Laplacian on an nx × ny × nz grid, with `diagonal` instead of 6): SPD for a
// diagonal above 6, with many supernodes under nested dissection.
inline Eigen::SparseMatrix<double> grid_laplacian(int nx, int ny, int nz, double stiffness = 1.0,
                                                  double diagonal = 6.1) {
  const int n = nx * ny * nz;
  auto id = [&](int i, int j, int k) { return (k * ny + j) * nx + i; };
  std::vector<Eigen::Triplet<double>> t;
  const auto couple = [&](int p, int q) {
    t.emplace_back(p, q, -stiffness);
    t.emplace_back(q, p, -stiffness);
  };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int p = id(i, j, k);
        t.emplace_back(p, p, diagonal * stiffness);
        if (i + 1 < nx) couple(p, id(i + 1, j, k));
        if (j + 1 < ny) couple(p, id(i, j + 1, k));
        if (k + 1 < nz) couple(p, id(i, j, k + 1));
      }
  Eigen::SparseMatrix<double> K(n, n);
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

// Runs `call`, which must throw an InputError whose message holds each of `parts` (`what`: the case, for
// the failure message).
template <class Call>
void expect_input_error(Call call, std::initializer_list<const char*> parts, const char* what) {
  try {
    call();
    ADD_FAILURE() << what << ": no InputError";
  } catch (const InputError& e) {
    for (const char* part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

// Appends `from`'s elements with their nodes shifted by `offset`, new tags and `from_groups`' groups.
template <std::size_t N>
void append_elements(const std::vector<std::array<int, N>>& from, const std::vector<int>& from_groups, int offset,
                     std::vector<std::array<int, N>>& to, std::vector<std::size_t>& tags, std::vector<int>& groups) {
  for (std::size_t e = 0; e < from.size(); ++e) {
    std::array<int, N> moved = from[e];
    for (int& v : moved) v += offset;
    to.push_back(moved);
    tags.push_back(tags.empty() ? 1 : tags.back() + 1);
    groups.push_back(from_groups[e]);
  }
}

// `mesh` with copies of itself moved by each of `shifts` appended (nodes, tetrahedra and boundary
// triangles, with their groups): 1 + shifts.size() parts that share no node.
inline Mesh with_moved_copies(const Mesh& mesh, const std::vector<Eigen::Vector3d>& shifts) {
  Mesh all = mesh;
  for (const Eigen::Vector3d& shift : shifts) {
    const int offset = static_cast<int>(all.nodes.size());
    for (std::size_t v = 0; v < mesh.nodes.size(); ++v) {
      all.nodes.push_back(mesh.nodes[v] + shift);
      all.node_tags.push_back(all.node_tags.empty() ? 1 : all.node_tags.back() + 1);
    }
    append_elements(mesh.tets, mesh.tet_group, offset, all.tets, all.tet_tags, all.tet_group);
    append_elements(mesh.triangles, mesh.triangle_group, offset, all.triangles, all.triangle_tags, all.triangle_group);
  }
  return all;
}
inline Mesh with_moved_copy(const Mesh& mesh, const Eigen::Vector3d& shift) { return with_moved_copies(mesh, {shift}); }

// Section 6 of the paper on the built-in five-tet brick at n = 4 (override with mesh.n).
inline const char* paper_scene_text() {
  return R"(
[mesh]
generator = "paper_brick"
n = 4
[material]
young = 21.19e10
poisson = 0.277
[boundary]
clamped = ["clamped"]
contact = ["contact"]
[[boundary.traction]]
group = "load_end"
value = [1e7, 0, 2e7]
[[boundary.traction]]
group = "load_top"
value = [0, 0, -3e7]
[friction]
slip_bound = 2e7
law = "ramp"
param = 6e4
)";
}

struct RandomQp {
  Eigen::MatrixXd Q;
  BoxDiscQP qp;  // qp.Q is left null: point it at Q where the object will live (use_operator)
  // Points qp at Q and sets ‖Q‖ (power iteration, 5% margin): call once the object stays put.
  void use_operator() {
    qp.Q = &Q;
    qp.q_norm = 1.05 * estimate_norm(Q, 200);
  }
};

// `a`'s QP as a matrix-free one: the same Q (which must outlive it), seen only through products and
// its diagonal.
inline BoxDiscQP matrix_free_copy(const RandomQp& a) {
  BoxDiscQP qp = a.qp;
  qp.Q = nullptr;
  const Eigen::MatrixXd* Q = &a.Q;
  qp.product = [Q](const Eigen::VectorXd& v) { return Eigen::VectorXd(*Q * v); };
  qp.q_diagonal = a.Q.diagonal();
  qp.q_norm = 1.05 * estimate_norm(a.Q);
  return qp;
}

// Q = AᵀA + shift·I with A Gaussian (m+extra_rows) x m, h Gaussian, radii uniform in [0, 2)
// with every fifth disc a point (c = 0).
inline RandomQp make_random_qp(int r, bool friction, unsigned seed, int extra_rows = 3, double shift = 0.05) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const int m = friction ? 3 * r : r;
  Eigen::MatrixXd A(m + extra_rows, m);
  for (int i = 0; i < A.rows(); ++i)
    for (int j = 0; j < A.cols(); ++j) A(i, j) = normal(gen);
  RandomQp out;
  out.Q = A.transpose() * A + shift * Eigen::MatrixXd::Identity(m, m);
  out.qp.r = r;
  out.qp.with_friction = friction;
  out.qp.h.resize(m);
  for (int i = 0; i < m; ++i) out.qp.h[i] = 3 * normal(gen);
  out.qp.radius.resize(r);
  for (int i = 0; i < r; ++i) out.qp.radius[i] = i % 5 == 4 ? 0.0 : 2 * uniform(gen);
  return out;
}

// A vector of n standard normal entries.
inline Eigen::VectorXd random_vector(Eigen::Index n, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal;
  Eigen::VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v[i] = normal(gen);
  return v;
}

// The stability check's factor of Q in double (for make_bordered_newton).
inline std::shared_ptr<DualOperatorFactor> double_factor(const Eigen::MatrixXd& Q) {
  auto f = std::make_shared<DualOperatorFactor>();
  f->in_double.emplace(Q);
  return f;
}

}  // namespace contact3d::testing
