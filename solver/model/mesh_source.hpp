// Obtains the scene's mesh: reads an .msh file, runs gmsh on a .geo script (with the
// scene's -setnumber parameters, output kept in the run's folder), or builds the paper's
// five-tet brick in memory.
#pragma once

#include <filesystem>

#include "mesh/mesh.hpp"
#include "model/scene.hpp"

namespace contact3d {

// `work_dir` receives mesh.msh and gmsh.log when gmsh runs.
Mesh load_scene_mesh(const MeshSource& source, const std::filesystem::path& work_dir);

// Runs gmsh: geo -> msh (format "msh41" or "msh22"). Throws InputError with gmsh's log tail.
void run_gmsh(const std::filesystem::path& geo, const std::map<std::string, double>& parameters,
              const std::filesystem::path& out_msh, const std::string& format = "msh41");

}  // namespace contact3d
