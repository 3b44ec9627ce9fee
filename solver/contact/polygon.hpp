// Convex polygons in the contact plane, carried with the barycentric coordinates of each
// vertex in the triangle they were cut from, so that P1 functions of that triangle can be
// integrated exactly over them. Clipping by a linear level function keeps the part where
// the level is <= 0 (Sutherland–Hodgman for one half-plane).
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

namespace contact3d {

struct PolygonVertex {
  Eigen::Vector2d xy;
  Eigen::Vector3d bary;  // barycentric coordinates in the source triangle
};
using Polygon = std::vector<PolygonVertex>;

// The whole triangle (a, b, c) as a polygon.
Polygon triangle_polygon(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c);

// Keep the part where level(v) <= 0; `levels` holds one value per vertex of a function that
// is linear over the polygon.
Polygon clip_by_levels(const Polygon& poly, const std::vector<double>& levels);

// Keep the part inside the axis-aligned box [lo, hi].
Polygon clip_to_box(Polygon poly, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi);

double polygon_area(const Polygon& poly);
// ∫_poly bary_k dS for k = 0,1,2: the exact integrals of the triangle's three hat functions.
Eigen::Vector3d hat_integrals(const Polygon& poly);
// ∫_poly f dS and ∫_poly f² dS for f linear, given by its values at the vertices.
double integral_linear(const Polygon& poly, const std::vector<double>& values);
double integral_linear_squared(const Polygon& poly, const std::vector<double>& values);
// ∫_poly G(f) dS for f linear (vertex values) and G linear over the range f takes on poly:
// each fan triangle contributes its area times G at its centroid (exact under that premise,
// and G is only ever evaluated strictly inside the polygon).
double integral_of_linear_composed(const Polygon& poly, const std::vector<double>& values,
                                   const std::function<double(double)>& G);

}  // namespace contact3d
