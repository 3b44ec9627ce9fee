// Obtains the scene's mesh: reads a mesh file (.msh, or FreeFEM's Medit .mesh/.meshb), runs gmsh
// on a .geo script (with the scene's -setnumber parameters) or FreeFEM on an .edp meshing script
// (`-out FILE -<key> <value>`; it must savemesh its mesh3 to FILE), output kept in the run's
// folder, or builds the paper's five-tet brick in memory. Scripts are code: see MeshSource::trusted.
#pragma once

#include <filesystem>

#include "mesh/mesh.hpp"
#include "model/scene.hpp"

namespace contact3d {

// `work_dir` receives mesh.msh and gmsh.log when gmsh runs, mesh.mesh and freefem.log for FreeFEM.
Mesh load_scene_mesh(const MeshSource& source, const std::filesystem::path& work_dir);

// Whether `log` is a mesher's log a run wrote (its first line says so): a later run removes only those,
// with their mesh, not a user's own gmsh.log beside a mesh of theirs (`gmsh -log gmsh.log` in a folder
// used with output.dir = ".", whose log a solve of that mesh removed).
bool written_by_a_run(const std::filesystem::path& log);

// Runs gmsh: geo -> msh (format "msh41" or "msh22"). Throws InputError with gmsh's log tail.
void run_gmsh(const std::filesystem::path& geo, const std::map<std::string, double>& parameters,
              const std::filesystem::path& out_msh, const std::string& format = "msh41");

// Runs FreeFEM's meshing script: edp -> Medit file `out_mesh`. Throws InputError with the log's tail.
void run_freefem_mesher(const std::filesystem::path& edp, const std::map<std::string, double>& parameters,
                        const std::filesystem::path& out_mesh);

}  // namespace contact3d
