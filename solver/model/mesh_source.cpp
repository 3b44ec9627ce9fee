#include "model/mesh_source.hpp"

#include <cctype>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base/errors.hpp"
#include "base/format.hpp"
#include "mesh/brick_generator.hpp"
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
  if (s.size() <= chars) return s;
  const std::size_t from = s.find('\n', s.size() - chars);  // whole lines
  return from == std::string::npos ? s.substr(s.size() - chars) : s.substr(from + 1);
}

// The first line of a mesher's log a run writes (written_by_a_run).
constexpr const char* kRunLogMark = "# contact3d ran:";

// `text` cut to at most `bytes` at a character's start (a path in a log may be UTF-8), marked " …".
std::string shortened(const std::string& text, std::size_t bytes) {
  if (text.size() <= bytes) return text;
  while (bytes > 0 && (static_cast<unsigned char>(text[bytes]) & 0xC0) == 0x80) --bytes;
  return text.substr(0, bytes) + " …";
}

// The first line of the log that reports an error ("Error" in gmsh's, "Error" or "error" in FreeFEM's),
// with what to make of it, or "" (a script's first mistake often leaves a cascade of later ones, and
// the log's tail then shows only those).
std::string first_error_line(const std::filesystem::path& log) {
  std::ifstream in(log);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(kRunLogMark, 0) != 0 &&
        (line.find("Error") != std::string::npos || line.find("error") != std::string::npos))
      return "its first error: " + shortened(line, 300) + "; ";
  return "";
}

// Runs a mesher (argv[0] from PATH) with its output in `log`; an InputError with the log's tail
// when it fails or does not produce `product`.
void run_mesher(std::vector<std::string> args, const std::filesystem::path& script,
                const std::filesystem::path& product, const std::filesystem::path& log) {
  const std::string program = args.front();
  std::string command;  // the log's first line: the whole command, its -setnumber values with it
  for (const std::string& arg : args) command += (command.empty() ? "" : " ") + arg;
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("cannot start " + program + " (fork failed)");
  if (pid == 0) {
    // The mesher dies with the solve: a solve killed while gmsh meshed left gmsh running, and it wrote its
    // mesh.msh into the folder after a later run had finished there.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);  // the solve died before the line above
    std::FILE* f = std::fopen(log.c_str(), "w");
    if (f) {
      std::fprintf(f, "%s %s\n", kRunLogMark, command.c_str());
      std::fflush(f);
      dup2(fileno(f), 1);
      dup2(fileno(f), 2);
    }
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execvp(program.c_str(), argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !std::filesystem::exists(product)) {
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    const std::string how = WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status)) + " (" +
                                                      strsignal(WTERMSIG(status)) + ")"
                                                : "exit " + std::to_string(code);
    throw InputError(code == 127 ? program + " is not installed (run `make deps`)"
                                 : program + " failed on '" + script.string() + "' (" + how + "); " +
                                       first_error_line(log) + "end of " + log.string() + ":\n" + tail_of(log));
  }
}

// Comments removed, so that a keyword in a comment does not count (and one hidden behind a
// comment marker inside a string is still seen: strings are kept). gmsh and FreeFEM share C++'s.
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

// What an untrusted script of each kind may not do: run programs, include files outside its folder.
struct ScriptRules {
  const char* kind;    // "gmsh script", "FreeFEM script"
  std::regex runs;     // a call that runs another program
  std::regex include;  // an include, with the file name as group 1
};
const ScriptRules& gmsh_rules() {
  static const ScriptRules r{"gmsh script",
                             std::regex(R"(\b(SystemCall|NonBlockingSystemCall|Shell|NonBlockingShell|OnelabRun)\b)"),
                             std::regex(R"re(\bInclude\s*"([^"]*)")re")};
  return r;
}
const ScriptRules& freefem_rules() {
  static const ScriptRules r{"FreeFEM script", std::regex(R"(\b(exec|system)\s*\()"),
                             std::regex(R"re(\binclude\s*"([^"]*)")re")};
  return r;
}

// The policy for untrusted scripts (MeshSource::trusted), applied to the script and every file it includes.
void check_script_is_safe(const std::filesystem::path& script, const std::filesystem::path& root,
                          const ScriptRules& rules, int depth = 0) {
  std::ifstream in(script);
  if (!in) throw InputError(std::string(rules.kind) + " '" + script.string() + "' cannot be read");
  std::stringstream buf;
  buf << in.rdbuf();
  const std::string code = without_comments(buf.str());
  std::smatch m;
  if (std::regex_search(code, m, rules.runs))
    throw InputError(std::string(rules.kind) + " '" + script.string() + "' calls '" + m[1].str() +
                     "', which runs other programs; a scene's script is not trusted to do that unless [mesh] sets "
                     "trusted = true");
  for (auto it = std::sregex_iterator(code.begin(), code.end(), rules.include); it != std::sregex_iterator(); ++it) {
    const std::filesystem::path target = std::filesystem::weakly_canonical(script.parent_path() / (*it)[1].str());
    const auto rel = target.lexically_relative(root);
    if (rel.empty() || *rel.begin() == "..")
      throw InputError(std::string(rules.kind) + " '" + script.string() + "' includes '" + (*it)[1].str() +
                       "', outside its folder '" + root.string() + "'; set [mesh] trusted = true to allow it");
    if (depth < 16) check_script_is_safe(target, root, rules, depth + 1);
  }
}

// The script's code without comments, with that of the files it includes (from its folder, as far as
// they can be read; each file once, whatever the includes' cycles).
std::string code_with_includes(const std::filesystem::path& script, const ScriptRules& rules,
                               std::set<std::filesystem::path>& read) {
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(script, ec);
  if (ec || !read.insert(canonical).second) return "";
  std::ifstream in(script);
  std::stringstream buf;
  buf << in.rdbuf();
  std::string code = without_comments(buf.str());
  const std::string own = code;
  for (auto it = std::sregex_iterator(own.begin(), own.end(), rules.include); it != std::sregex_iterator(); ++it)
    code += "\n" + code_with_includes(script.parent_path() / (*it)[1].str(), rules, read);
  return code;
}

// Each of mesh.parameters must be a name the script reads: gmsh's -setnumber and FreeFEM's -name value
// set what the script never mentions without a word (mesh.parameters.hh = 0.02 meshed at the script's
// own h = 0.08, exit 0).
void require_parameters_read(const std::filesystem::path& script, const std::map<std::string, double>& parameters,
                             const ScriptRules& rules) {
  std::set<std::filesystem::path> read;
  const std::string code = code_with_includes(script, rules, read);
  const auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (const auto& [name, value] : parameters) {
    bool mentioned = false;
    for (std::size_t at = code.find(name); at != std::string::npos && !mentioned; at = code.find(name, at + 1))
      mentioned =
          (at == 0 || !word(code[at - 1])) && (at + name.size() == code.size() || !word(code[at + name.size()]));
    if (!mentioned)
      throw InputError("mesh.parameters." + name + " = " + number(value) + ": the " + rules.kind + " '" +
                       script.string() + "' never mentions '" + name +
                       "', so it would be ignored and the mesh made with the script's own values; check the name "
                       "against the variables the script reads");
  }
}

void require_script(const std::filesystem::path& script, const char* kind, bool trusted, const ScriptRules& rules) {
  if (!std::filesystem::exists(script))
    throw InputError(std::string(kind) + " '" + script.string() + "' does not exist");
  // A named pipe would be read by the safety check and the mesher, or block both with no writer.
  if (std::error_code ec; !std::filesystem::is_regular_file(script, ec))
    throw InputError(std::string(kind) + " '" + script.string() +
                     "' is not a regular file (a folder, pipe or device): give the script's file");
  if (!trusted) check_script_is_safe(script, std::filesystem::weakly_canonical(script).parent_path(), rules);
}

}  // namespace

void run_gmsh(const std::filesystem::path& geo, const std::map<std::string, double>& parameters,
              const std::filesystem::path& out_msh, const std::string& format) {
  if (!std::filesystem::exists(geo)) throw InputError("gmsh script '" + geo.string() + "' does not exist");
  // -v 4: gmsh's information lines too (its version, the meshing steps and their times), so that the
  // log beside the results is one (with -v 2 it held only contact3d's line on a good run).
  std::vector<std::string> args = {"gmsh", "-3", "-format", format, "-v", "4"};
  for (const auto& [k, v] : parameters) args.insert(args.end(), {"-setnumber", k, format_number(v)});
  args.insert(args.end(), {geo.string(), "-o", out_msh.string()});
  run_mesher(args, geo, out_msh, out_msh.parent_path() / "gmsh.log");
}

void run_freefem_mesher(const std::filesystem::path& edp, const std::map<std::string, double>& parameters,
                        const std::filesystem::path& out_mesh) {
  if (!std::filesystem::exists(edp)) throw InputError("FreeFEM script '" + edp.string() + "' does not exist");
  // FreeFEM's plugins (msh3, ...) live in /usr/lib/freefem++ on Debian while its .pref points elsewhere.
  if (!std::getenv("FF_LOADPATH")) setenv("FF_LOADPATH", "/usr/lib/freefem++", 0);
  std::vector<std::string> args = {"FreeFem++", "-nw", "-v", "0", edp.string(), "-out", out_mesh.string()};
  for (const auto& [k, v] : parameters) args.insert(args.end(), {"-" + k, format_number(v)});
  run_mesher(args, edp, out_mesh, out_mesh.parent_path() / "freefem.log");
}

namespace {

// A mesh a mesher just wrote. On a full disk gmsh cuts its file short and still exits 0: a reading error
// there is said as the full disk it is (it read as "line 11289: unexpected end of file").
Mesh read_written_mesh(const std::filesystem::path& file, const std::string& mesher) {
  try {
    return read_mesh_file(file.string());
  } catch (const InputError& e) {
    std::error_code ec;
    const std::filesystem::space_info space = std::filesystem::space(file.parent_path(), ec);
    if (!ec && space.available < (1u << 20))
      throw InputError("cannot write '" + file.string() + "': no space left on its device (" +
                       std::to_string(space.available) + " bytes free); " + mesher + " wrote the mesh cut short (" +
                       e.what() + "); free space or choose another output folder");
    // A file-size limit (ulimit -f) cuts the file at the limit: gmsh, its SIGXFSZ ignored, exits 0.
    struct rlimit limit {};
    const std::uintmax_t size = std::filesystem::file_size(file, ec);
    if (!ec && getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY && size >= limit.rlim_cur)
      throw InputError("cannot write '" + file.string() + "': it reached the file-size limit of this process (" +
                       std::to_string(limit.rlim_cur) + " bytes, ulimit -f); " + mesher +
                       " wrote the mesh cut short (" + e.what() + "); raise the limit or use a coarser mesh");
    throw;
  }
}

}  // namespace

bool written_by_a_run(const std::filesystem::path& log) {
  std::ifstream in(log);
  std::string first;
  return std::getline(in, first) && first.rfind(kRunLogMark, 0) == 0;
}

Mesh load_scene_mesh(const MeshSource& source, const std::filesystem::path& work_dir) {
  if (!source.generator.empty()) return make_paper_brick(BrickSize{source.n});
  if (!source.geo.empty()) {
    require_script(source.geo, "gmsh script", source.trusted, gmsh_rules());
    require_parameters_read(source.geo, source.parameters, gmsh_rules());
    std::filesystem::create_directories(work_dir);
    const auto msh = work_dir / "mesh.msh";
    std::filesystem::remove(msh);
    run_gmsh(source.geo, source.parameters, msh);
    return read_written_mesh(msh, "gmsh");
  }
  if (!source.edp.empty()) {
    require_script(source.edp, "FreeFEM script", source.trusted, freefem_rules());
    require_parameters_read(source.edp, source.parameters, freefem_rules());
    std::filesystem::create_directories(work_dir);
    const auto mesh = work_dir / "mesh.mesh";
    std::filesystem::remove(mesh);
    run_freefem_mesher(source.edp, source.parameters, mesh);
    return read_written_mesh(mesh, "FreeFEM");
  }
  return read_mesh_file(source.file.string());
}

}  // namespace contact3d
