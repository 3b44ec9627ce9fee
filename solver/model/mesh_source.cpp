#include "model/mesh_source.hpp"

#include <fstream>
#include <regex>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

#include "base/errors.hpp"
#include "mesh/brick_generator.hpp"
#include "mesh/msh_reader.hpp"
#include "mesh/read_mesh.hpp"

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

// Comments removed, so that a keyword in a comment does not count (and one hidden behind a
// comment marker inside a string is still seen: strings are kept).
std::string without_comments(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    if (text.compare(i, 2, "//") == 0) {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (text.compare(i, 2, "/*") == 0) {
      const std::size_t end = text.find("*/", i + 2);
      i = end == std::string::npos ? text.size() : end + 2;
    } else {
      out += text[i++];
    }
  }
  return out;
}

// The policy for untrusted .geo scripts (MeshSource::trusted), applied to the script and to every
// file it includes.
void check_geo_is_safe(const std::filesystem::path& geo, const std::filesystem::path& root, int depth = 0) {
  std::ifstream in(geo);
  if (!in) throw InputError("gmsh script '" + geo.string() + "' cannot be read");
  std::stringstream buf;
  buf << in.rdbuf();
  const std::string code = without_comments(buf.str());
  static const std::regex run(R"(\b(SystemCall|NonBlockingSystemCall|Shell|NonBlockingShell|OnelabRun|SetChanged)\b)");
  std::smatch m;
  if (std::regex_search(code, m, run))
    throw InputError("gmsh script '" + geo.string() + "' calls '" + m[1].str() +
                     "', which runs other programs; a scene's .geo is not trusted to do that unless [mesh] sets "
                     "trusted = true");
  static const std::regex include(R"re(\bInclude\s*"([^"]*)")re");
  for (auto it = std::sregex_iterator(code.begin(), code.end(), include); it != std::sregex_iterator(); ++it) {
    const std::filesystem::path target = std::filesystem::weakly_canonical(geo.parent_path() / (*it)[1].str());
    const auto rel = target.lexically_relative(root);
    if (rel.empty() || *rel.begin() == "..")
      throw InputError("gmsh script '" + geo.string() + "' includes '" + (*it)[1].str() + "', outside its folder '" +
                       root.string() + "'; set [mesh] trusted = true to allow it");
    if (depth < 16) check_geo_is_safe(target, root, depth + 1);
  }
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
    if (!std::filesystem::exists(source.geo)) throw InputError("gmsh script '" + source.geo.string() + "' does not exist");
    if (!source.trusted)
      check_geo_is_safe(source.geo, std::filesystem::weakly_canonical(source.geo).parent_path());
    std::filesystem::create_directories(work_dir);
    const auto msh = work_dir / "mesh.msh";
    std::filesystem::remove(msh);
    run_gmsh(source.geo, source.parameters, msh);
    return read_msh(msh.string());
  }
  return read_mesh_file(source.file.string());
}

}  // namespace contact3d
