// The rectangles that cut Γc into the cells of T_H (partition.hpp), in the foundation's plane.
// Either a uniform grid of H_x × H_y rectangles over the face's bounding box (the paper's T_H),
// or — where H is given as a multiple k of the element size ("2h", "auto") and the contact mesh is
// graded (refined where the body touches, as for a Hertz contact) — the leaves of quadtrees on a
// coarse grid, each leaf about k local element extents wide in each direction. A uniform H on a
// graded mesh leaves the coarse part's cells without a node of their own (the stability condition
// (5.1) fails) or puts the whole refined zone into a cell or two.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace contact3d {

struct Box {
  Eigen::Vector2d lo, hi;
  Eigen::Vector2d extent() const { return hi - lo; }
  double area() const { return extent().x() * extent().y(); }
};

// A contact mesh is graded when the 90th percentile of its triangles' sizes (the larger extent of
// each projected triangle), the triangles counted alike or weighted by their area, is more than this
// many times the 10th percentile counted alike: a mesh refined along a line has most of its triangles
// fine and most of its area coarse (a half-cylinder meshed at 1.5 mm within 2 cm of its contact line,
// 5 cm elsewhere: a uniform grid of twice the median size left 81 356 of 89 178 cells without a node).
// Uniform and mildly varying meshes (gmsh's unstructured ones spread by under 2) keep the uniform grid.
constexpr double kGradedSpread = 3.0;

bool is_graded(const std::vector<Box>& triangles);

// At most this many rectangles, uniform or graded: a finer T_H has no use and would not fit (a graded
// one asked for with a tiny k, e.g. "0.01h", is refused before it is built, and while it is built).
constexpr double kMaxRectangles = 4e6;

class GridBoxes {
 public:
  // nx × ny rectangles over [lo, lo + extent]; box j·nx + i.
  static GridBoxes uniform(const Eigen::Vector2d& lo, const Eigen::Vector2d& extent, int nx, int ny);
  // Quadtree leaves over [lo, lo + extent]: a rectangle is halved along x while it is at least 1.5 k
  // times the median x-extent of the triangles it meets (along y the same), so a leaf is 0.75 to
  // 1.5 k of them. The coarse grid under the trees has rectangles of k times the 10th percentile of
  // the extents doubled until they reach k times the largest extents (it may reach past the face),
  // so the finest leaves are k times the finest extents.
  static GridBoxes graded(const Eigen::Vector2d& lo, const Eigen::Vector2d& extent, const std::vector<Box>& triangles,
                          const Eigen::Vector2d& k);

  int size() const { return graded_ ? static_cast<int>(leaves_.size()) : nx_ * ny_; }
  Box box(int id) const;
  // The boxes whose closure meets the rectangle [lo, hi], ascending.
  std::vector<int> overlapping(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) const;
  bool graded() const { return graded_; }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  Eigen::Vector2d base_size() const { return base_; }  // sides of the (coarse) grid's rectangles

 private:
  struct Node {
    Box box;
    int first_child = -1;  // children are consecutive: 2 or 4 of them
    int children = 0;
    int leaf = -1;
  };
  void split(int node, const std::vector<int>& triangles, const std::vector<Box>& all, const Eigen::Vector2d& k,
             int depth);
  void collect(int node, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, std::vector<int>& out) const;
  std::pair<int, int> base_range(double lo, double hi, double origin, double side, int n) const;

  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero(), base_ = Eigen::Vector2d::Zero();
  int nx_ = 0, ny_ = 0;
  bool graded_ = false;
  std::vector<Node> nodes_;  // graded: the trees, roots 0 .. nx·ny − 1 in grid order
  std::vector<int> leaves_;  // graded: node of each box, trees in grid order, each depth first
};

}  // namespace contact3d
