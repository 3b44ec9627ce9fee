#include "model/mesh_source.hpp"

#include <fstream>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

#include "base/errors.hpp"
#include "mesh/brick_generator.hpp"
#include "mesh/msh_reader.hpp"

namespace contact3d {
namespace {

std::string format_number(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

std::string tail_of(const std::filesystem::path& log, std::size_t chars = 800) {
  std::ifstream in(log);
  std::stringstream buf;
  buf << in.rdbuf();
  const std::string s = buf.str();
  return s.size() > chars ? s.substr(s.size() - chars) : s;
}

}  // namespace

void run_gmsh(const std::filesystem::path& geo, const std::map<std::string, double>& parameters,
              const std::filesystem::path& out_msh, const std::string& format) {
  if (!std::filesystem::exists(geo)) throw InputError("gmsh script '" + geo.string() + "' does not exist");
  std::vector<std::string> args = {"gmsh", "-3", "-format", format, "-v", "2"};
  for (const auto& [k, v] : parameters) {
    args.insert(args.end(), {"-setnumber", k, format_number(v)});
  }
  args.insert(args.end(), {geo.string(), "-o", out_msh.string()});
  const std::filesystem::path log = out_msh.parent_path() / "gmsh.log";
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("cannot start gmsh (fork failed)");
  if (pid == 0) {
    std::FILE* f = std::fopen(log.c_str(), "w");
    if (f) { dup2(fileno(f), 1); dup2(fileno(f), 2); }
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execvp("gmsh", argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !std::filesystem::exists(out_msh)) {
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    throw InputError(code == 127 ? "gmsh is not installed (run `make deps`)"
                                 : "gmsh failed on '" + geo.string() + "' (exit " + std::to_string(code) +
                                       "); end of " + log.string() + ":\n" + tail_of(log));
  }
}

Mesh load_scene_mesh(const MeshSource& source, const std::filesystem::path& work_dir) {
  if (!source.generator.empty()) return make_paper_brick(BrickSize{source.n});
  if (!source.geo.empty()) {
    std::filesystem::create_directories(work_dir);
    const auto msh = work_dir / "mesh.msh";
    std::filesystem::remove(msh);
    run_gmsh(source.geo, source.parameters, msh);
    return read_msh(msh.string());
  }
  return read_msh(source.file.string());
}

}  // namespace contact3d
