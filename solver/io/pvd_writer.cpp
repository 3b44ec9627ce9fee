#include "io/pvd_writer.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>

#include "base/errors.hpp"
#include "io/atomic_file.hpp"
#include "io/results_writer.hpp"
#include "io/vtu_format.hpp"

namespace contact3d {
namespace {

std::string step_name(int k) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "contact_step_%03d.vtu", k);
  return buf;
}

}  // namespace

int write_solution_steps(const std::filesystem::path& dir, const Scene& scene, const Mesh& mesh, const SolveResult& res) {
  if (res.face.triangles.empty()) return 0;
  std::vector<int> local(mesh.nodes.size(), -1), global;
  for (const auto& tri : res.face.triangles)
    for (int v : tri)
      if (local[v] < 0) { local[v] = static_cast<int>(global.size()); global.push_back(v); }
  const std::size_t n = global.size(), m = res.face.triangles.size();
  const std::filesystem::path steps = dir / "steps";
  std::error_code ec;
  std::filesystem::remove_all(steps, ec);  // stale steps of an earlier, longer run would mislead
  std::filesystem::create_directories(steps, ec);
  if (ec) throw InputError("cannot create '" + steps.string() + "': " + ec.message());

  const int count = static_cast<int>(res.u_history.size());
  std::vector<int> history_index(mesh.nodes.size(), 0);
  for (std::size_t j = 0; j < res.history_nodes.size(); ++j) history_index[res.history_nodes[j]] = static_cast<int>(j);
  for (int k = 1; k <= count; ++k) {
    const Eigen::VectorXd& u = res.u_history[k - 1];
    auto ui = [&](std::size_t i, int c) { return u[3 * history_index[global[i]] + c]; };
    auto in_plane = [&](std::size_t i) -> Eigen::Vector3d {  // in the foundation plane's frame
      return res.frame.to_local(u.segment<3>(3 * history_index[global[i]]));
    };
    write_file(steps / step_name(k), [&](std::ostream& out) {
      vtu::begin_piece(out, n, m);
      out << "      <PointData Scalars=\"slip_norm\" Vectors=\"displacement\">\n";
      vtu::data_array(out, "displacement", 3, n, ui);
      vtu::data_array(out, "gap", 1, n, [&](std::size_t i, int) {
        return res.frame.to_local_point(mesh.nodes[global[i]]).z() + in_plane(i).z();
      });
      vtu::data_array(out, "slip", 3, n, [&](std::size_t i, int c) { return tangential_part(res.frame, in_plane(i))[c]; });
      vtu::data_array(out, "slip_norm", 1, n, [&](std::size_t i, int) { return std::hypot(in_plane(i).x(), in_plane(i).y()); });
      vtu::data_array(out, "friction_coefficient", 1, n, [&](std::size_t i, int) {
        return scene.frictionless() ? 0.0 : scene.law(std::hypot(in_plane(i).x(), in_plane(i).y()));
      });
      out << "      </PointData>\n";
      vtu::geometry(
          out, n, [&](std::size_t i, int c) { return mesh.nodes[global[i]][c]; }, m, 3,
          [&](std::size_t e, int a) { return local[res.face.triangles[e][a]]; }, 5);
      vtu::end_piece(out);
    });
  }

  write_file(dir / "solution.pvd", [&](std::ostream& pvd) {
    pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "  <Collection>\n";
    for (int k = 1; k <= count; ++k)
      pvd << "    <DataSet timestep=\"" << k << "\" group=\"\" part=\"0\" file=\"steps/" << step_name(k) << "\"/>\n";
    if (count > 0) pvd << "    <DataSet timestep=\"" << count << "\" group=\"\" part=\"1\" file=\"body.vtu\"/>\n";
    pvd << "  </Collection>\n</VTKFile>\n";
  });
  return count;
}

}  // namespace contact3d
