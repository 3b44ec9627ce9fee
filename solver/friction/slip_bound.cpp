#include "friction/slip_bound.hpp"

#include <algorithm>

namespace contact3d {
namespace {

std::vector<double> vertex_values(const Polygon& poly, const Eigen::Vector3d& corner_values) {
  std::vector<double> v(poly.size());
  for (std::size_t k = 0; k < poly.size(); ++k) v[k] = poly[k].bary.dot(corner_values);
  return v;
}

// ∫_poly F(φ) dS with φ linear on poly (corner values in the source triangle): cut poly at
// each breakpoint b into {φ <= b} and {φ >= b}; on each slab F∘φ is linear.
double integrate_law(Polygon poly, const Eigen::Vector3d& phi, const FrictionLaw& law,
                     const std::vector<double>& breaks) {
  const std::function<double(double)> F = [&law](double t) { return law(t); };
  double total = 0;
  for (double b : breaks) {
    if (poly.empty()) break;
    const std::vector<double> values = vertex_values(poly, phi);
    // φ ≡ b on the whole piece (a face held at rest at a law's breakpoint 0, or moved by exactly t0):
    // both clips below would keep all of it and count it twice (radii of 2·F(0)·g); it is F(b)'s.
    if (std::all_of(values.begin(), values.end(), [b](double v) { return v == b; })) {
      total += integral_of_linear_composed(poly, values, F);
      return total;
    }
    std::vector<double> below(values.size()), above(values.size());
    for (std::size_t k = 0; k < values.size(); ++k) {
      below[k] = values[k] - b;
      above[k] = b - values[k];
    }
    const Polygon lower = clip_by_levels(poly, below);
    if (!lower.empty()) total += integral_of_linear_composed(lower, vertex_values(lower, phi), F);
    poly = clip_by_levels(poly, above);
  }
  if (!poly.empty()) total += integral_of_linear_composed(poly, vertex_values(poly, phi), F);
  return total;
}

}  // namespace

Eigen::VectorXd disc_radii(const ContactFace& face, const Partition& partition, const FrictionLaw& law,
                           double slip_bound, const Eigen::VectorXd& phi_nodes) {
  const auto breaks = law.breakpoints();
  Eigen::VectorXd c(partition.cells.size());
  for (std::size_t i = 0; i < partition.cells.size(); ++i) {
    const auto& cell = partition.cells[i];
    double integral = 0;
    for (const auto& piece : cell.pieces) {
      const auto& tri = face.triangles[piece.triangle];
      const Eigen::Vector3d phi(phi_nodes[tri[0]], phi_nodes[tri[1]], phi_nodes[tri[2]]);
      integral += integrate_law(piece.polygon, phi, law, breaks);
    }
    c[i] = slip_bound * integral / cell.area;
  }
  return c;
}

}  // namespace contact3d
