#include "contact/partition.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "contact/grid_boxes.hpp"

namespace contact3d {
namespace {

Eigen::Vector2d xy(const Mesh& m, int v) { return m.nodes[v].head<2>(); }

// A cell's area, bounding box and area centroid (∫x dS / area, exact per piece: the vertex average
// is a clipped trapezoid's or pentagon's centroid only by chance).
void finish_cell(ContactCell& cell) {
  cell.area = 0;
  Eigen::Vector2d moment = Eigen::Vector2d::Zero();
  cell.lo = Eigen::Vector2d::Constant(INFINITY);
  cell.hi = Eigen::Vector2d::Constant(-INFINITY);
  for (const auto& piece : cell.pieces) {
    std::vector<double> xs, ys;
    for (const auto& v : piece.polygon) {
      xs.push_back(v.xy.x());
      ys.push_back(v.xy.y());
      cell.lo = cell.lo.cwiseMin(v.xy);
      cell.hi = cell.hi.cwiseMax(v.xy);
    }
    moment += Eigen::Vector2d(integral_linear(piece.polygon, xs), integral_linear(piece.polygon, ys));
    cell.area += polygon_area(piece.polygon);
  }
  cell.centroid = cell.area > 0 ? Eigen::Vector2d(moment / cell.area) : cell.lo;
}

// Do two convex polygons share a boundary segment longer than tol? (Pieces come from exact
// clipping, so a common boundary is collinear up to rounding.)
bool share_segment(const Polygon& a, const Polygon& b, double tol) {
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector2d p = a[i].xy, q = a[(i + 1) % a.size()].xy;
    const double len = (q - p).norm();
    if (len <= tol) continue;
    const Eigen::Vector2d d = (q - p) / len, nrm(-d.y(), d.x());
    for (std::size_t j = 0; j < b.size(); ++j) {
      const Eigen::Vector2d r = b[j].xy, s = b[(j + 1) % b.size()].xy;
      if (std::abs(nrm.dot(r - p)) > tol || std::abs(nrm.dot(s - p)) > tol) continue;
      const double t0 = d.dot(r - p), t1 = d.dot(s - p);
      const double overlap = std::min(len, std::max(t0, t1)) - std::max(0.0, std::min(t0, t1));
      if (overlap > tol) return true;
    }
  }
  return false;
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
};

// Maximum matching of cells (rows) to columns by augmenting paths (Kuhn); returns the
// unmatched rows.
std::vector<int> unmatched_rows(const std::vector<std::vector<int>>& adj, int n_cols) {
  std::vector<int> match_col(n_cols, -1);
  std::vector<int> seen(n_cols, -1);
  std::vector<int> unmatched;
  // Depth-first search for an augmenting path from `root`, with an explicit stack (no recursion:
  // paths can be long on big faces). Frame k holds a row and the column it was reached through.
  struct Frame {
    int row;
    std::size_t next;
    int via_col;
  };
  std::vector<Frame> stack;
  auto augment = [&](int root, int stamp) {
    stack.assign(1, Frame{root, 0, -1});
    while (!stack.empty()) {
      Frame& top = stack.back();
      if (top.next == adj[top.row].size()) {
        stack.pop_back();
        continue;
      }
      const int c = adj[top.row][top.next++];
      if (seen[c] == stamp) continue;
      seen[c] = stamp;
      if (match_col[c] < 0) {  // flip the path: every row on the stack takes the next column
        int col = c;
        for (std::size_t k = stack.size(); k-- > 0;) {
          match_col[col] = stack[k].row;
          col = stack[k].via_col;
        }
        return true;
      }
      stack.push_back(Frame{match_col[c], 0, c});
    }
    return false;
  };
  // Greedy first pass: most cells match their own node at once.
  std::vector<char> done(adj.size(), 0);
  for (std::size_t r = 0; r < adj.size(); ++r)
    for (int c : adj[r])
      if (match_col[c] < 0) {
        match_col[c] = static_cast<int>(r);
        done[r] = 1;
        break;
      }
  for (std::size_t r = 0; r < adj.size(); ++r)
    if (!done[r] && !augment(static_cast<int>(r), static_cast<int>(r))) unmatched.push_back(static_cast<int>(r));
  return unmatched;
}

// (5.1) needs a free contact node of its own in every cell (enforce_stability matches them), and
// merging repairs at most max_repair_fraction of the cells; the cells that cover the face number at
// least its area / (H_x·H_y). Where even that many leave more cells without a node than merging
// repairs, the partition is refused. Where that many cells take long to build, it is said before
// they are built, which took minutes for an H given in the wrong unit (the brick with h = 0.25 m:
// H = 0.003 m, 333 000 cells, still building after 100 s; H = 0.005 m, 120 000 cells, 18.5 s before
// (5.1) refused them; 30 000 cells, 1.1 s); fewer are built and refused naming the cells without a node.
constexpr double kCellsRefusedBeforeBuilding = 5e4;
void require_a_node_per_cell_possible(const ContactFace& face, double size_x, double size_y,
                                      const PartitionOptions& opt) {
  const double fewest_cells = face.area / (size_x * size_y);
  const double nodes = static_cast<double>(face.nodes.size());
  if (!(fewest_cells > kCellsRefusedBeforeBuilding)) return;
  if (!(fewest_cells - nodes > std::max(1.0, opt.max_repair_fraction * fewest_cells))) return;
  throw InputError("contact.cell_size " + number(size_x) + (size_y != size_x ? " x " + number(size_y) : "") + " " +
                   opt.length_unit + " puts at least " + number(fewest_cells, 3) + " cells on the contact face (area " +
                   number(face.area, 4) + "), but it has " + std::to_string(face.nodes.size()) +
                   " free contact nodes and the stability condition (5.1) needs one of its own in every cell: the "
                   "contact mesh's size is h = " +
                   number(face.h, 3) + "; choose H of about 2h (\"2h\", the default) or check the unit of the H given");
}

// The rectangles: graded where H is k·h and the contact mesh is graded, else the uniform grid of
// ceil(L/H) rectangles per direction.
GridBoxes grid_boxes(const ContactFace& face, const std::vector<Box>& triangles, const PartitionOptions& opt) {
  const Eigen::Vector2d extent = face.hi - face.lo;
  if (opt.per_element_size > 0 && is_graded(triangles))
    return GridBoxes::graded(face.lo, extent, triangles, Eigen::Vector2d::Constant(opt.per_element_size));
  const double size_y = opt.cell_size_y > 0 ? opt.cell_size_y : opt.cell_size;
  if (!std::isfinite(size_y)) throw InputError("contact.cell_size must be finite");
  const double nx = std::max(1.0, std::ceil(extent.x() / opt.cell_size - 1e-9));
  const double ny = std::max(1.0, std::ceil(extent.y() / size_y - 1e-9));
  if (nx * ny > kMaxRectangles)
    throw InputError("contact.cell_size " + number(opt.cell_size) + " " + opt.length_unit + " gives " +
                     number(nx * ny, 3) + " cells (at most " + number(kMaxRectangles, 3) + "); choose a larger H");
  require_a_node_per_cell_possible(face, opt.cell_size, size_y, opt);
  return GridBoxes::uniform(face.lo, extent, static_cast<int>(nx), static_cast<int>(ny));
}

}  // namespace

std::string describe_cell_sizes(const Partition& part) {
  if (!part.graded) return "H = " + number(part.hx) + " x " + number(part.hy) + " " + part.length_unit;
  return "H from " + number(part.smallest_box.x(), 3) + " x " + number(part.smallest_box.y(), 3) + " to " +
         number(part.largest_box.x(), 3) + " x " + number(part.largest_box.y(), 3) + " " + part.length_unit +
         ", following the contact mesh's element size";
}

std::string describe_regions(int regions) {
  return regions > 1 ? "; each within one of " + std::to_string(regions) + " regions of Γc by material and flat part"
                     : std::string();
}

std::string describe_cell(const Partition& part, int i) {
  const auto& c = part.cells[i];
  std::ostringstream s;
  s << "cell " << i << " [" << c.lo.x() << ", " << c.hi.x() << "] x [" << c.lo.y() << ", " << c.hi.y() << "], area "
    << c.area;
  return s.str();
}

namespace {

// make_grid_partition's steps on the state they share: the clipped pieces, their adjacency, and the
// union-find of pieces into cells. build() reads as the algorithm.
class GridPartitionBuilder {
 public:
  GridPartitionBuilder(const Mesh& mesh, const ContactFace& face, const PartitionOptions& opt,
                       const std::vector<int>& region_of_triangle, const ComponentsHeld& held)
      : mesh_(mesh), face_(face), opt_(opt), region_of_triangle_(region_of_triangle), held_(held) {}

  Partition build() {
    if (!(opt_.cell_size > 0) || !std::isfinite(opt_.cell_size))
      throw InputError("contact.cell_size must be a positive length, got " + std::to_string(opt_.cell_size));
    if (face_.triangles.empty()) throw InputError("the contact face has no triangles");
    if (!region_of_triangle_.empty() && region_of_triangle_.size() != face_.triangles.size())
      throw std::invalid_argument("make_grid_partition: one region per contact triangle expected");
    part_.length_unit = opt_.length_unit;
    part_.regions =
        std::max(1, static_cast<int>(std::set<int>(region_of_triangle_.begin(), region_of_triangle_.end()).size()));
    lay_out_rectangles();
    clip_triangles_to_rectangles();
    refuse_overlapping_triangles();
    link_adjacent_pieces();
    form_initial_cells();
    merge_slivers();
    std::vector<int> root_of_cell = collect_cells();
    if (opt_.enforce_stability) enforce_stability(root_of_cell);
    return std::move(part_);
  }

 private:
  // The rectangles (one grid, or quadtree leaves on a graded mesh) over the triangles' bounding boxes.
  void lay_out_rectangles() {
    for (const auto& tri : face_.triangles) {
      whole_triangles_.push_back(triangle_polygon(xy(mesh_, tri[0]), xy(mesh_, tri[1]), xy(mesh_, tri[2])));
      Box b{whole_triangles_.back()[0].xy, whole_triangles_.back()[0].xy};
      for (const auto& v : whole_triangles_.back()) {
        b.lo = b.lo.cwiseMin(v.xy);
        b.hi = b.hi.cwiseMax(v.xy);
      }
      triangle_boxes_.push_back(b);
    }
    boxes_.emplace(grid_boxes(face_, triangle_boxes_, opt_));
    part_.grid_nx = boxes_->nx();
    part_.grid_ny = boxes_->ny();
    part_.hx = boxes_->base_size().x();
    part_.hy = boxes_->base_size().y();
    part_.graded = boxes_->graded();
    if (!(part_.hx > 0) || !(part_.hy > 0)) throw InputError("the contact face has zero area (it is a line)");
  }

  // 1. Every contact triangle clipped to the rectangles its bounding box meets.
  void clip_triangles_to_rectangles() {
    pieces_of_triangle_.resize(face_.triangles.size());
    for (std::size_t t = 0; t < face_.triangles.size(); ++t) {
      const Polygon& whole = whole_triangles_[t];
      const double tiny = 1e-12 * polygon_area(whole);
      for (int b : boxes_->overlapping(triangle_boxes_[t].lo, triangle_boxes_[t].hi)) {
        const Box box = boxes_->box(b);
        Polygon piece = clip_to_box(whole, box.lo, box.hi);
        if (piece.empty() || polygon_area(piece) <= tiny) continue;
        pieces_of_triangle_[t].push_back(static_cast<int>(pieces_.size()));
        pieces_.push_back({static_cast<int>(t), std::move(piece), b});
      }
    }
    if (pieces_.empty()) throw InputError("the contact face has zero area");
    part_.smallest_box = Eigen::Vector2d::Constant(INFINITY);
    for (const CellPiece& piece : pieces_) {  // the rectangles that cut the face
      part_.smallest_box = part_.smallest_box.cwiseMin(boxes_->box(piece.box).extent());
      part_.largest_box = part_.largest_box.cwiseMax(boxes_->box(piece.box).extent());
    }
  }

  // Γc must be a graph over the plane: its triangles' projections tile it without overlapping. Where
  // they cover more of a rectangle than the rectangle itself, two of them lie over one another: two
  // volumes meshed into one space without being joined (two gmsh boxes without BooleanFragments solved
  // in silence, with 6 m² of contact on a 4.25 m² footprint) or a face reaching under itself. Each
  // cell would average both.
  void refuse_overlapping_triangles() const {
    std::map<int, double> covered;
    for (const CellPiece& piece : pieces_) covered[piece.box] += polygon_area(piece.polygon);
    for (const auto& [b, area] : covered) {
      const Box box = boxes_->box(b);
      if (!(area > (1 + 1e-6) * box.area())) continue;
      const auto point = [&](const Eigen::Vector2d& x) {
        return "(" + number(x.x(), 4) + ", " + number(x.y(), 4) + ")";
      };
      throw InputError("the contact face overlaps itself: over the rectangle " + point(box.lo) + " – " + point(box.hi) +
                       " (" + opt_.length_unit + ", in the plane's frame) its triangles cover " +
                       number(area / box.area(), 3) +
                       " times the rectangle's area; Γc must be a graph over the plane z = 0, seen from below. Two "
                       "volumes occupy the same place without being joined (gmsh: BooleanFragments or Coherence), "
                       "or the contact groups hold two faces one above the other: keep only the lowest");
    }
  }

  // Piece adjacency: a common boundary segment; candidates are pieces of one triangle and of
  // triangles sharing a mesh edge.
  void link_adjacent_pieces() {
    const Eigen::Vector2d extent = face_.hi - face_.lo;
    const double tol = 1e-9 * std::max(face_.h, 1e-12 * extent.norm());
    adj_.resize(pieces_.size());
    const auto link = [&](int a, int b) {
      if (a == b || !share_segment(pieces_[a].polygon, pieces_[b].polygon, tol)) return;
      adj_[a].push_back(b);
      adj_[b].push_back(a);
    };
    std::map<std::pair<int, int>, std::vector<int>> triangles_of_edge;
    for (std::size_t t = 0; t < face_.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        const int a = face_.triangles[t][k], b = face_.triangles[t][(k + 1) % 3];
        triangles_of_edge[{std::min(a, b), std::max(a, b)}].push_back(static_cast<int>(t));
      }
    for (const auto& list : pieces_of_triangle_)
      for (std::size_t x = 0; x < list.size(); ++x)
        for (std::size_t y = x + 1; y < list.size(); ++y) link(list[x], list[y]);
    for (const auto& [edge, tris] : triangles_of_edge)
      for (std::size_t x = 0; x < tris.size(); ++x)
        for (std::size_t y = x + 1; y < tris.size(); ++y)
          for (int a : pieces_of_triangle_[tris[x]])
            for (int b : pieces_of_triangle_[tris[y]]) link(a, b);
  }

  // 2. Initial cells: the pieces of one rectangle, split into connected components.
  void form_initial_cells() {
    uf_ = UnionFind(pieces_.size());
    std::map<std::pair<int, int>, int> first_of_box;
    for (std::size_t p = 0; p < pieces_.size(); ++p)
      if (!opt_.split_disconnected) {
        auto [it, fresh] =
            first_of_box.emplace(std::pair(pieces_[p].box, region(static_cast<int>(p))), static_cast<int>(p));
        if (!fresh) uf_.parent[uf_.find(static_cast<int>(p))] = uf_.find(it->second);
      } else {
        for (int q : adj_[p])
          if (pieces_[q].box == pieces_[p].box && region(q) == region(static_cast<int>(p)))
            uf_.parent[uf_.find(static_cast<int>(p))] = uf_.find(q);
      }
    std::map<int, std::vector<int>> roots_of_box;
    for (std::size_t p = 0; p < pieces_.size(); ++p) {
      auto& roots = roots_of_box[pieces_[p].box];
      const int r = uf_.find(static_cast<int>(p));
      if (std::find(roots.begin(), roots.end(), r) == roots.end()) roots.push_back(r);
    }
    for (const auto& [box, roots] : roots_of_box) part_.split_cells += static_cast<int>(roots.size()) - 1;
    area_.assign(pieces_.size(), 0.0);  // by root
    for (std::size_t p = 0; p < pieces_.size(); ++p)
      area_[uf_.find(static_cast<int>(p))] += polygon_area(pieces_[p].polygon);
  }

  std::vector<int> roots() {
    std::vector<int> out;
    for (std::size_t p = 0; p < pieces_.size(); ++p)
      if (uf_.find(static_cast<int>(p)) == static_cast<int>(p)) out.push_back(static_cast<int>(p));
    return out;
  }

  int region(int piece) const {
    return region_of_triangle_.empty() ? 0 : region_of_triangle_[static_cast<std::size_t>(pieces_[piece].triangle)];
  }

  // Merges cell `root` into its adjacent cell of largest area, one of its own region where it has
  // such a neighbour; false if it has none.
  bool merge_into_largest_neighbour(int root) {
    int best = -1;
    bool best_same = false;
    for (std::size_t p = 0; p < pieces_.size(); ++p) {
      if (uf_.find(static_cast<int>(p)) != root) continue;
      for (int q : adj_[p]) {
        const int rq = uf_.find(q);
        const bool same = region(q) == region(root);
        if (rq != root && (best < 0 || (same && !best_same) || (same == best_same && area_[rq] > area_[best])))
          best = rq, best_same = same;
      }
    }
    if (best < 0) return false;
    uf_.parent[root] = best;
    area_[best] += area_[root];
    return true;
  }

  // 3. Slivers, smallest first; a merged cell that is still small is visited again. A cell's full
  // rectangle is the one of its first piece (graded rectangles differ in size).
  void merge_slivers() {
    const auto full = [&](int root) {
      return part_.graded ? boxes_->box(pieces_[root].box).area() : part_.hx * part_.hy;
    };
    for (bool changed = true; changed;) {
      changed = false;
      std::vector<int> small;
      for (int r : roots())
        if (area_[r] < opt_.sliver_fraction * full(r)) small.push_back(r);
      std::sort(small.begin(), small.end(), [&](int a, int b) { return area_[a] < area_[b]; });
      for (int r : small) {
        if (uf_.find(r) != r || area_[r] >= opt_.sliver_fraction * full(r)) continue;
        if (merge_into_largest_neighbour(r)) {
          ++part_.merged_slivers;
          changed = true;
        }
      }
    }
  }

  // The cells from the union-find, ordered by their first rectangle (grid order), then by first
  // piece; returns the root of each cell.
  std::vector<int> collect_cells() {
    part_.cells.clear();
    std::map<int, int> cell_of_root;
    std::vector<int> order = roots();
    std::vector<int> first_box(pieces_.size(), INT32_MAX);
    for (std::size_t p = 0; p < pieces_.size(); ++p) {
      const int r = uf_.find(static_cast<int>(p));
      first_box[r] = std::min(first_box[r], pieces_[p].box);
    }
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return first_box[a] < first_box[b]; });
    for (int r : order) {
      cell_of_root[r] = static_cast<int>(part_.cells.size());
      part_.cells.emplace_back();
    }
    for (std::size_t p = 0; p < pieces_.size(); ++p)
      part_.cells[cell_of_root[uf_.find(static_cast<int>(p))]].pieces.push_back(pieces_[p]);
    for (auto& cell : part_.cells) finish_cell(cell);
    return order;
  }

  // 4. Structural (5.1): every cell needs a free contact node of its own. Cells without one are
  // merged into a neighbour, one at a time (one merge may fix several); where that cannot be done,
  // the partition is refused.
  void enforce_stability(std::vector<int>& root_of_cell) {
    for (int round = 0;; ++round) {
      const std::vector<int> bad = cells_without_own_node(face_, part_, held_);
      if (bad.empty()) return;
      const bool repairable = round < 1000 && static_cast<double>(bad.size()) <=
                                                  std::max(1.0, opt_.max_repair_fraction * part_.cells.size());
      bool merged = false;
      if (repairable)
        for (int c : bad)
          if (uf_.find(root_of_cell[c]) == root_of_cell[c] && merge_into_largest_neighbour(root_of_cell[c])) {
            ++part_.stability_merges;
            merged = true;
            break;  // re-match after each merge: one merge may fix several cells
          }
      if (!merged) {
        // A cell one of whose rows acts on no free component at all (every node of it holds that
        // component) fails at any cell size: left to the contact operator's refusal, which names the
        // component and the conditions (model/contact_solver.cpp, require_free_contact_rows).
        const auto rows = cell_node_weights(face_, part_);
        if (std::any_of(bad.begin(), bad.end(), [&](int c) { return row_without_free_component(rows[c]); })) return;
        std::string cells;
        for (std::size_t k = 0; k < bad.size() && k < 8; ++k) cells += "\n  " + describe_cell(part_, bad[k]);
        throw InputError(
            "the multiplier partition violates the stability condition (5.1): " + std::to_string(bad.size()) + " of " +
            std::to_string(part_.cells.size()) +
            " cells have no free contact node of their own (one whose z is free for the normal row; with "
            "friction also one whose x, and one whose y, is free for the tangential rows) (rectangles " +
            describe_cell_sizes(part_) + ", contact mesh size h = " + number(face_.h) + " " + opt_.length_unit +
            "), e.g." + cells + "\nuse a larger contact.cell_size (H), e.g. \"2h\" or more");
      }
      root_of_cell = collect_cells();
    }
  }

  // True where one of a cell's rows (normal; tangential with friction) has no node of the cell (`nodes`,
  // its cell_node_weights) whose component it acts on is free.
  bool row_without_free_component(const std::vector<std::pair<int, double>>& nodes) const {
    for (const int component : held_.row_components())
      if (std::none_of(nodes.begin(), nodes.end(), [&](const auto& entry) {
            return face_.contact_index[static_cast<std::size_t>(entry.first)] >= 0 &&
                   held_.is_free(entry.first, component);
          }))
        return true;
    return false;
  }

  const Mesh& mesh_;
  const ContactFace& face_;
  const PartitionOptions& opt_;
  const std::vector<int>& region_of_triangle_;  // empty: one region
  const ComponentsHeld& held_;
  Partition part_;
  std::vector<Polygon> whole_triangles_;  // the contact triangles in the plane
  std::vector<Box> triangle_boxes_;       // and their bounding boxes
  std::optional<GridBoxes> boxes_;
  std::vector<CellPiece> pieces_;                     // a triangle clipped to one rectangle
  std::vector<std::vector<int>> pieces_of_triangle_;  // indices into pieces_
  std::vector<std::vector<int>> adj_;                 // pieces sharing a boundary segment
  UnionFind uf_{0};                                   // pieces into cells
  std::vector<double> area_;                          // a cell's area, at its root piece
};

}  // namespace

Partition make_grid_partition(const Mesh& mesh, const ContactFace& face, const PartitionOptions& opt,
                              const std::vector<int>& triangle_region, const ComponentsHeld& held) {
  return GridPartitionBuilder(mesh, face, opt, triangle_region, held).build();
}

std::vector<std::vector<std::pair<int, double>>> cell_node_weights(const ContactFace& face,
                                                                   const Partition& partition) {
  std::vector<std::vector<std::pair<int, double>>> rows(partition.cells.size());
  for (std::size_t i = 0; i < partition.cells.size(); ++i) {
    std::map<int, double> acc;
    for (const auto& piece : partition.cells[i].pieces) {
      const Eigen::Vector3d w = hat_integrals(piece.polygon);
      for (int k = 0; k < 3; ++k) acc[face.triangles[piece.triangle][k]] += w[k];
    }
    rows[i].assign(acc.begin(), acc.end());
  }
  return rows;
}

std::vector<int> cells_without_own_node(const ContactFace& face, const Partition& partition,
                                        const ComponentsHeld& held) {
  const auto rows = cell_node_weights(face, partition);
  std::set<int> unmatched;
  for (const int component : held.row_components()) {
    std::vector<std::vector<int>> adj(rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i)
      for (const auto& [node, w] : rows[i]) {
        const int c = node < static_cast<int>(face.contact_index.size()) ? face.contact_index[node] : -1;
        if (c >= 0 && held.is_free(node, component) && w > 1e-12 * partition.cells[i].area) adj[i].push_back(c);
      }
    for (const int cell : unmatched_rows(adj, static_cast<int>(face.nodes.size()))) unmatched.insert(cell);
  }
  return {unmatched.begin(), unmatched.end()};
}

namespace {

// Graded rectangles: runs of `size` cells along a Z-order (Morton) curve through the centroids, so
// each aggregate is a compact patch whatever the cells' sizes.
std::vector<int> aggregates_along_z_order(const Partition& partition, int size, int& count) {
  const std::size_t r = partition.cells.size();
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY), hi = -lo;
  for (const ContactCell& cell : partition.cells) {
    lo = lo.cwiseMin(cell.centroid);
    hi = hi.cwiseMax(cell.centroid);
  }
  const Eigen::Vector2d span = (hi - lo).cwiseMax(Eigen::Vector2d::Constant(1e-300));
  auto morton = [&](const Eigen::Vector2d& p) {
    const auto cx = static_cast<std::uint32_t>(std::min(65535.0, 65535.0 * (p.x() - lo.x()) / span.x()));
    const auto cy = static_cast<std::uint32_t>(std::min(65535.0, 65535.0 * (p.y() - lo.y()) / span.y()));
    std::uint64_t key = 0;
    for (int b = 0; b < 16; ++b)
      key |= (static_cast<std::uint64_t>((cx >> b) & 1u) << (2 * b)) |
             (static_cast<std::uint64_t>((cy >> b) & 1u) << (2 * b + 1));
    return key;
  };
  std::vector<int> order(r);
  std::iota(order.begin(), order.end(), 0);
  std::vector<std::uint64_t> key(r);
  for (std::size_t i = 0; i < r; ++i) key[i] = morton(partition.cells[i].centroid);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key[a] < key[b]; });
  std::vector<int> aggregate(r, 0);
  for (std::size_t k = 0; k < r; ++k) aggregate[order[k]] = static_cast<int>(k) / size;
  count = static_cast<int>((r + size - 1) / size);
  return aggregate;
}

}  // namespace

std::vector<int> cell_aggregates(const Partition& partition, int cells_per_side, int& count) {
  const std::size_t r = partition.cells.size();
  std::vector<int> aggregate(r, 0);
  count = r > 0 ? 1 : 0;
  if (r == 0 || cells_per_side <= 0 || partition.grid_nx <= 0) return aggregate;
  if (partition.graded) return aggregates_along_z_order(partition, cells_per_side * cells_per_side, count);
  std::map<std::pair<int, int>, int> number;
  for (std::size_t i = 0; i < r; ++i) {
    int box = INT32_MAX;  // the cell's first grid rectangle (a merged cell spans several)
    for (const CellPiece& piece : partition.cells[i].pieces) box = std::min(box, piece.box);
    if (box == INT32_MAX) box = 0;
    const std::pair<int, int> key{box % partition.grid_nx / cells_per_side, box / partition.grid_nx / cells_per_side};
    aggregate[i] = number.try_emplace(key, static_cast<int>(number.size())).first->second;
  }
  count = static_cast<int>(number.size());
  return aggregate;
}

}  // namespace contact3d
