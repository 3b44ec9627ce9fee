#include "contact/polygon.hpp"

#include <cmath>

namespace contact3d {

Polygon triangle_polygon(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return {{a, Eigen::Vector3d(1, 0, 0)}, {b, Eigen::Vector3d(0, 1, 0)}, {c, Eigen::Vector3d(0, 0, 1)}};
}

Polygon clip_by_levels(const Polygon& poly, const std::vector<double>& levels) {
  Polygon out;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    const double li = levels[i], lj = levels[j];
    if (li <= 0) out.push_back(poly[i]);
    if ((li < 0 && lj > 0) || (li > 0 && lj < 0)) {
      const double s = li / (li - lj);
      out.push_back({poly[i].xy + s * (poly[j].xy - poly[i].xy), poly[i].bary + s * (poly[j].bary - poly[i].bary)});
    }
  }
  if (out.size() < 3) out.clear();
  return out;
}

Polygon clip_to_box(Polygon poly, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  for (int axis = 0; axis < 2 && !poly.empty(); ++axis) {
    for (int side = 0; side < 2 && !poly.empty(); ++side) {
      std::vector<double> levels(poly.size());
      for (std::size_t i = 0; i < poly.size(); ++i)
        levels[i] = side == 0 ? lo[axis] - poly[i].xy[axis] : poly[i].xy[axis] - hi[axis];
      poly = clip_by_levels(poly, levels);
    }
  }
  return poly;
}

namespace {
double fan_area(const Polygon& p, std::size_t k) {
  const Eigen::Vector2d a = p[k].xy - p[0].xy, b = p[k + 1].xy - p[0].xy;
  return 0.5 * (a.x() * b.y() - a.y() * b.x());
}
}  // namespace

double polygon_area(const Polygon& poly) {
  double area = 0;
  for (std::size_t k = 1; k + 1 < poly.size(); ++k) area += fan_area(poly, k);
  return std::abs(area);
}

Eigen::Vector3d hat_integrals(const Polygon& poly) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t k = 1; k + 1 < poly.size(); ++k)
    sum += std::abs(fan_area(poly, k)) * (poly[0].bary + poly[k].bary + poly[k + 1].bary) / 3.0;
  return sum;
}

double integral_linear(const Polygon& poly, const std::vector<double>& v) {
  double sum = 0;
  for (std::size_t k = 1; k + 1 < poly.size(); ++k) sum += std::abs(fan_area(poly, k)) * (v[0] + v[k] + v[k + 1]) / 3.0;
  return sum;
}

double integral_linear_squared(const Polygon& poly, const std::vector<double>& v) {
  double sum = 0;
  for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
    const double a = v[0], b = v[k], c = v[k + 1];
    sum += std::abs(fan_area(poly, k)) / 6.0 * (a * a + b * b + c * c + a * b + b * c + a * c);
  }
  return sum;
}

double integral_of_linear_composed(const Polygon& poly, const std::vector<double>& v,
                                   const std::function<double(double)>& G) {
  double sum = 0;
  for (std::size_t k = 1; k + 1 < poly.size(); ++k)
    sum += std::abs(fan_area(poly, k)) * G((v[0] + v[k] + v[k + 1]) / 3.0);
  return sum;
}

}  // namespace contact3d
