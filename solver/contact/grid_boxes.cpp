#include "contact/grid_boxes.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "base/errors.hpp"
#include "base/format.hpp"

namespace contact3d {
namespace {

// Deeper than any grading a mesh generator makes (2^-24 of the coarse rectangle).
constexpr int kMaxDepth = 24;

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Open overlap: boxes that only touch along an edge do not meet.
bool meet(const Box& a, const Box& b) {
  return a.lo.x() < b.hi.x() && b.lo.x() < a.hi.x() && a.lo.y() < b.hi.y() && b.lo.y() < a.hi.y();
}

[[noreturn]] void too_many_rectangles(const Eigen::Vector2d& k, std::size_t triangles) {
  throw InputError("contact.cell_size = \"" + number(k.x()) + "h\" on this graded contact mesh (" +
                   std::to_string(triangles) + " triangles) asks for more than " + number(kMaxRectangles) +
                   " rectangles; choose a larger multiple of h, e.g. \"2h\"");
}

}  // namespace

namespace {

// The size below which `share` of the weight lies, the sizes weighted by `weight` (or counted alike).
double weighted_percentile(std::vector<std::pair<double, double>> size_weight, double share) {
  std::sort(size_weight.begin(), size_weight.end());
  double total = 0;
  for (const auto& sw : size_weight) total += sw.second;
  double below = 0;
  for (const auto& [size, weight] : size_weight)
    if ((below += weight) >= share * total) return size;
  return size_weight.back().first;
}

}  // namespace

bool is_graded(const std::vector<Box>& triangles) {
  if (triangles.size() < 10) return false;
  std::vector<std::pair<double, double>> by_count, by_area;
  by_count.reserve(triangles.size());
  by_area.reserve(triangles.size());
  for (const Box& t : triangles) {
    by_count.emplace_back(t.extent().maxCoeff(), 1.0);
    by_area.emplace_back(t.extent().maxCoeff(), t.area());
  }
  const double finest = weighted_percentile(by_count, 0.1);
  const double coarse = std::max(weighted_percentile(by_count, 0.9), weighted_percentile(by_area, 0.9));
  return coarse > kGradedSpread * finest;
}

GridBoxes GridBoxes::uniform(const Eigen::Vector2d& lo, const Eigen::Vector2d& extent, int nx, int ny) {
  GridBoxes g;
  g.origin_ = lo;
  g.nx_ = nx;
  g.ny_ = ny;
  g.base_ = Eigen::Vector2d(extent.x() / nx, extent.y() / ny);
  return g;
}

GridBoxes GridBoxes::graded(const Eigen::Vector2d& lo, const Eigen::Vector2d& extent, const std::vector<Box>& triangles,
                            const Eigen::Vector2d& k) {
  GridBoxes g;
  g.graded_ = true;
  g.origin_ = lo;
  // The coarse rectangles: the finest target (k times the 10th percentile of the extents) doubled,
  // in both directions alike (the leaves keep the finest elements' aspect), until it reaches k times
  // the largest extents, so that halving them lands on the finest target where the mesh is finest.
  Eigen::Vector2d finest, largest;
  for (int d = 0; d < 2; ++d) {
    std::vector<double> e;
    e.reserve(triangles.size());
    for (const Box& t : triangles) e.push_back(t.extent()[d]);
    largest[d] = *std::max_element(e.begin(), e.end());
    std::nth_element(e.begin(), e.begin() + e.size() / 10, e.end());
    finest[d] = std::max(e[e.size() / 10], 1e-12 * largest[d]);
  }
  Eigen::Vector2d side = k.cwiseProduct(finest);
  while (side.x() < k.x() * largest.x() || side.y() < k.y() * largest.y()) side *= 2;
  g.nx_ = static_cast<int>(std::max(1.0, std::ceil(extent.x() / side.x() - 1e-9)));
  g.ny_ = static_cast<int>(std::max(1.0, std::ceil(extent.y() / side.y() - 1e-9)));
  if (static_cast<double>(g.nx_) * g.ny_ > kMaxRectangles) too_many_rectangles(k, triangles.size());
  g.base_ = side;  // the grid may reach past the face: rectangles there get no pieces
  std::vector<std::vector<int>> of_root(static_cast<std::size_t>(g.nx_) * g.ny_);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto [i0, i1] = g.base_range(triangles[t].lo.x(), triangles[t].hi.x(), lo.x(), g.base_.x(), g.nx_);
    const auto [j0, j1] = g.base_range(triangles[t].lo.y(), triangles[t].hi.y(), lo.y(), g.base_.y(), g.ny_);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) of_root[static_cast<std::size_t>(j) * g.nx_ + i].push_back(static_cast<int>(t));
  }
  for (int j = 0; j < g.ny_; ++j)
    for (int i = 0; i < g.nx_; ++i) {
      Node root;
      root.box.lo = Eigen::Vector2d(lo.x() + i * g.base_.x(), lo.y() + j * g.base_.y());
      root.box.hi = root.box.lo + g.base_;
      g.nodes_.push_back(root);
    }
  for (std::size_t r = 0; r < of_root.size(); ++r) g.split(static_cast<int>(r), of_root[r], triangles, k, 0);
  return g;
}

void GridBoxes::split(int node, const std::vector<int>& triangles, const std::vector<Box>& all,
                      const Eigen::Vector2d& k, int depth) {
  bool along_x = false, along_y = false;
  if (!triangles.empty() && depth < kMaxDepth) {
    std::vector<double> ex, ey;
    for (int t : triangles) {
      ex.push_back(all[t].extent().x());
      ey.push_back(all[t].extent().y());
    }
    const Eigen::Vector2d width = nodes_[node].box.extent();
    along_x = width.x() >= 1.5 * k.x() * median(ex);
    along_y = width.y() >= 1.5 * k.y() * median(ey);
  }
  if (!along_x && !along_y) {
    nodes_[node].leaf = static_cast<int>(leaves_.size());
    leaves_.push_back(node);
    return;
  }
  if (static_cast<double>(nodes_.size()) + 4 > kMaxRectangles) too_many_rectangles(k, all.size());
  const Box parent = nodes_[node].box;
  const Eigen::Vector2d mid = 0.5 * (parent.lo + parent.hi);
  const int first = static_cast<int>(nodes_.size());
  for (int b = 0; b < (along_y ? 2 : 1); ++b)
    for (int a = 0; a < (along_x ? 2 : 1); ++a) {
      Node child;
      child.box.lo = Eigen::Vector2d(a == 0 ? parent.lo.x() : mid.x(), b == 0 ? parent.lo.y() : mid.y());
      child.box.hi =
          Eigen::Vector2d(a == 0 && along_x ? mid.x() : parent.hi.x(), b == 0 && along_y ? mid.y() : parent.hi.y());
      nodes_.push_back(child);
    }
  nodes_[node].first_child = first;
  nodes_[node].children = static_cast<int>(nodes_.size()) - first;
  for (int c = first; c < first + nodes_[node].children; ++c) {
    std::vector<int> inside;
    for (int t : triangles)
      if (meet(all[t], nodes_[c].box)) inside.push_back(t);
    split(c, inside, all, k, depth + 1);
  }
}

std::pair<int, int> GridBoxes::base_range(double lo, double hi, double origin, double side, int n) const {
  const int a = std::clamp(static_cast<int>(std::floor((lo - origin) / side)), 0, n - 1);
  const int b = std::clamp(static_cast<int>(std::floor((hi - origin) / side)), 0, n - 1);
  return {a, b};
}

Box GridBoxes::box(int id) const {
  if (graded_) return nodes_[leaves_[id]].box;
  const int i = id % nx_, j = id / nx_;
  Box b;
  b.lo = Eigen::Vector2d(origin_.x() + i * base_.x(), origin_.y() + j * base_.y());
  b.hi = b.lo + base_;
  return b;
}

void GridBoxes::collect(int node, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, std::vector<int>& out) const {
  const Box& b = nodes_[node].box;
  if (b.hi.x() < lo.x() || hi.x() < b.lo.x() || b.hi.y() < lo.y() || hi.y() < b.lo.y()) return;
  if (nodes_[node].leaf >= 0) {
    out.push_back(nodes_[node].leaf);
    return;
  }
  for (int c = nodes_[node].first_child; c < nodes_[node].first_child + nodes_[node].children; ++c)
    collect(c, lo, hi, out);
}

std::vector<int> GridBoxes::overlapping(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const {
  const auto [i0, i1] = base_range(lo.x(), hi.x(), origin_.x(), base_.x(), nx_);
  const auto [j0, j1] = base_range(lo.y(), hi.y(), origin_.y(), base_.y(), ny_);
  std::vector<int> out;
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      if (graded_)
        collect(j * nx_ + i, lo, hi, out);
      else
        out.push_back(j * nx_ + i);
    }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace contact3d
