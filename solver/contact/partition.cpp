#include "contact/partition.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "io/errors.hpp"

namespace contact3d {
namespace {

Eigen::Vector2d xy(const Mesh& m, int v) { return m.nodes[v].head<2>(); }

void finish_cell(ContactCell& cell) {
  cell.area = 0;
  Eigen::Vector2d moment = Eigen::Vector2d::Zero();
  cell.lo = Eigen::Vector2d::Constant(INFINITY);
  cell.hi = Eigen::Vector2d::Constant(-INFINITY);
  for (const auto& piece : cell.pieces) {
    const double a = polygon_area(piece.polygon);
    Eigen::Vector2d c = Eigen::Vector2d::Zero();
    for (const auto& v : piece.polygon) {
      c += v.xy;
      cell.lo = cell.lo.cwiseMin(v.xy);
      cell.hi = cell.hi.cwiseMax(v.xy);
    }
    moment += a * c / static_cast<double>(piece.polygon.size());
    cell.area += a;
  }
  cell.centroid = cell.area > 0 ? Eigen::Vector2d(moment / cell.area) : cell.lo;
}

}  // namespace

Partition make_grid_partition(const Mesh& mesh, const ContactFace& face, const PartitionOptions& opt) {
  if (!(opt.cell_size > 0) || !std::isfinite(opt.cell_size))
    throw InputError("contact.cell_size must be a positive length, got " + std::to_string(opt.cell_size));
  Partition part;
  const Eigen::Vector2d extent = face.hi - face.lo;
  const double max_cells = 4e6;
  const double nx = std::max(1.0, std::ceil(extent.x() / opt.cell_size - 1e-9));
  const double ny = std::max(1.0, std::ceil(extent.y() / opt.cell_size - 1e-9));
  if (nx * ny > max_cells)
    throw InputError("contact.cell_size " + std::to_string(opt.cell_size) + " m gives " +
                     std::to_string(nx * ny) + " cells; choose a larger H");
  part.grid_nx = static_cast<int>(nx);
  part.grid_ny = static_cast<int>(ny);
  part.hx = extent.x() / nx;
  part.hy = extent.y() / ny;

  std::vector<ContactCell> grid(static_cast<std::size_t>(part.grid_nx) * part.grid_ny);
  auto cell_lo = [&](int i, int j) { return Eigen::Vector2d(face.lo.x() + i * part.hx, face.lo.y() + j * part.hy); };
  for (std::size_t t = 0; t < face.triangles.size(); ++t) {
    const auto& tri = face.triangles[t];
    const Polygon whole = triangle_polygon(xy(mesh, tri[0]), xy(mesh, tri[1]), xy(mesh, tri[2]));
    Eigen::Vector2d lo = whole[0].xy, hi = whole[0].xy;
    for (const auto& v : whole) { lo = lo.cwiseMin(v.xy); hi = hi.cwiseMax(v.xy); }
    const int i0 = std::clamp(static_cast<int>(std::floor((lo.x() - face.lo.x()) / part.hx)), 0, part.grid_nx - 1);
    const int i1 = std::clamp(static_cast<int>(std::floor((hi.x() - face.lo.x()) / part.hx)), 0, part.grid_nx - 1);
    const int j0 = std::clamp(static_cast<int>(std::floor((lo.y() - face.lo.y()) / part.hy)), 0, part.grid_ny - 1);
    const int j1 = std::clamp(static_cast<int>(std::floor((hi.y() - face.lo.y()) / part.hy)), 0, part.grid_ny - 1);
    const double tiny = 1e-12 * polygon_area(whole);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const Eigen::Vector2d clo = cell_lo(i, j), chi = clo + Eigen::Vector2d(part.hx, part.hy);
        Polygon piece = clip_to_box(whole, clo, chi);
        if (piece.empty() || polygon_area(piece) <= tiny) continue;
        grid[static_cast<std::size_t>(j) * part.grid_nx + i].pieces.push_back({static_cast<int>(t), std::move(piece)});
      }
  }
  for (auto& cell : grid) finish_cell(cell);

  // Merge slivers into the grid neighbour (4-neighbourhood) with the largest area.
  const double full = part.hx * part.hy;
  std::vector<int> owner(grid.size());
  for (std::size_t k = 0; k < grid.size(); ++k) owner[k] = static_cast<int>(k);
  for (int j = 0; j < part.grid_ny; ++j)
    for (int i = 0; i < part.grid_nx; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * part.grid_nx + i;
      if (grid[k].pieces.empty() || grid[k].area >= opt.sliver_fraction * full) continue;
      int best = -1;
      double best_area = 0;
      const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
      for (int d = 0; d < 4; ++d) {
        const int ii = i + di[d], jj = j + dj[d];
        if (ii < 0 || jj < 0 || ii >= part.grid_nx || jj >= part.grid_ny) continue;
        int target = owner[static_cast<std::size_t>(jj) * part.grid_nx + ii];
        if (grid[target].area > best_area) { best_area = grid[target].area; best = target; }
      }
      if (best < 0 || best_area <= grid[k].area) continue;  // no larger neighbour: keep it
      for (auto& p : grid[k].pieces) grid[best].pieces.push_back(std::move(p));
      grid[k].pieces.clear();
      finish_cell(grid[best]);
      for (auto& o : owner) if (o == static_cast<int>(k)) o = best;
      ++part.merged_slivers;
    }
  for (auto& cell : grid)
    if (!cell.pieces.empty()) part.cells.push_back(std::move(cell));
  if (part.cells.empty()) throw InputError("the contact face has zero area");
  return part;
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

}  // namespace contact3d
