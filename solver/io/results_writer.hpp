// Writes what every solve leaves in its output folder: summary.json, contact_nodes.csv,
// contact_cells.csv, history.csv and the ParaView files (body.vtu, contact.vtu, contact_cells.vtu,
// solution.pvd with its steps/). summary.json is written last: its presence marks a finished run.
#pragma once

#include <filesystem>

#include "linalg/blas_threads.hpp"
#include "mesh/mesh.hpp"
#include "model/contact_solver.hpp"
#include "model/scene.hpp"

namespace contact3d {

struct RunInfo {
  // How the run was started (summary.json's "run"): the build's version, the scene file and the mesh
  // given by --mesh as absolute paths, the --set overrides in order, the working directory.
  std::string version, scene_file, mesh_override, working_directory;
  std::vector<std::string> overrides;
  std::string mesh_description;  // where the mesh came from
  double mesh_seconds = 0;
  double total_seconds = 0;
  BlasThreadChoice blas;  // OpenBLAS's threads, fitted to the idle cores
};

void write_results(const std::filesystem::path& dir, const Scene& scene, const Mesh& mesh, const SolveResult& res,
                   const RunInfo& info);
// `output_seconds`: the time the other files took (tables, VTU, the collection), time_s.output;
// time_s.total ends where writing begins.
void write_summary_json(const std::filesystem::path& file, const Scene& scene, const Mesh& mesh, const SolveResult& res,
                        const RunInfo& info, double output_seconds);

}  // namespace contact3d
