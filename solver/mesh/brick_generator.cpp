#include "mesh/brick_generator.hpp"

#include <algorithm>
#include <cmath>

#include "base/errors.hpp"

namespace contact3d {
namespace {

double signed_volume(const Mesh& m, const std::array<int, 4>& t) {
  const Eigen::Vector3d a = m.nodes[t[1]] - m.nodes[t[0]];
  const Eigen::Vector3d b = m.nodes[t[2]] - m.nodes[t[0]];
  const Eigen::Vector3d c = m.nodes[t[3]] - m.nodes[t[0]];
  return a.dot(b.cross(c)) / 6.0;
}

// Local corners of a unit cube by (a,b,c) bits; the five-tet split for an "even" cube uses the
// four even-parity corners as the central tet; an "odd" cube is its mirror image in x.
using Corner = std::array<int, 3>;
const std::array<std::array<Corner, 4>, 5> kEvenSplit = {{
    {{{0, 0, 0}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1}}},  // central
    {{{1, 0, 0}, {0, 0, 0}, {1, 1, 0}, {1, 0, 1}}},
    {{{0, 1, 0}, {0, 0, 0}, {1, 1, 0}, {0, 1, 1}}},
    {{{0, 0, 1}, {0, 0, 0}, {1, 0, 1}, {0, 1, 1}}},
    {{{1, 1, 1}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1}}},
}};

}  // namespace

Mesh make_paper_brick(const BrickSize& s) {
  if (s.n < 1 || s.n > 64)
    throw InputError("brick: n must be between 1 and 64 (n = 64: 3.9M tets), got " + std::to_string(s.n));
  const int nx = 3 * s.n, ny = s.n, nz = s.n;
  Mesh m;
  auto node_id = [&](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        m.nodes.emplace_back(s.lx * i / nx, s.ly * j / ny, s.lz * k / nz);
        m.node_tags.push_back(m.nodes.size());
      }
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const bool odd = (i + j + k) % 2 == 1;
        for (const auto& local : kEvenSplit) {
          std::array<int, 4> t{};
          for (int v = 0; v < 4; ++v) {
            const int a = odd ? 1 - local[v][0] : local[v][0];
            t[v] = node_id(i + a, j + local[v][1], k + local[v][2]);
          }
          if (signed_volume(m, t) < 0) std::swap(t[2], t[3]);
          m.tets.push_back(t);
          m.tet_tags.push_back(m.tets.size());
          m.tet_group.push_back(6);
        }
      }
  m.groups = {{2, 1, "clamped"}, {2, 2, "load_end"}, {2, 3, "load_top"},
              {2, 4, "contact"}, {2, 5, "free"},     {3, 6, "body"}};
  const double eps = 1e-9;
  for (const auto& f : boundary_faces(m)) {
    Eigen::Vector3d lo = m.nodes[f[0]], hi = m.nodes[f[0]];
    for (int v : f) {
      lo = lo.cwiseMin(m.nodes[v]);
      hi = hi.cwiseMax(m.nodes[v]);
    }
    int tag = 5;
    if (hi.x() < eps)
      tag = 1;
    else if (lo.x() > s.lx - eps)
      tag = 2;
    else if (lo.z() > s.lz - eps)
      tag = 3;
    else if (hi.z() < eps)
      tag = 4;
    m.triangles.push_back(f);
    m.triangle_tags.push_back(m.tets.size() + m.triangles.size());
    m.triangle_group.push_back(tag);
  }
  return m;
}

}  // namespace contact3d
