#include "io/run_folder.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include "base/errors.hpp"
#include "io/atomic_file.hpp"
#include "io/pvd_writer.hpp"

namespace contact3d {
namespace {

// Whether `dir` is the output folder of a solve running now (its lock taken).
bool held_by_a_running_solve(const std::filesystem::path& dir) {
  const int fd = ::open((dir / ".contact3d.lock").c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool held = ::flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);
  return held;
}

// The previous run's report.md (written by pipeline/run_scene.py beside the solve's files, opening with
// kRunReportTitle), stale once the folder is solved again; a report.md of the user's own stays.
void remove_run_report(const std::filesystem::path& dir) {
  std::ifstream in(dir / "report.md");
  std::string first;
  if (!in || !std::getline(in, first) || first.rfind(kRunReportTitle, 0) != 0) return;
  in.close();
  std::error_code ec;
  std::filesystem::remove(dir / "report.md", ec);
}

}  // namespace

RunFolder::RunFolder(const std::filesystem::path& dir, const std::string& what) : dir_(dir) {
  std::error_code ec, made;
  std::filesystem::create_directories(dir, made);
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
    throw InputError("output folder '" + dir.string() + "' cannot be written: it is a file");
  if (made && !std::filesystem::is_directory(dir, ec))  // the reason it could not be made (a parent's permission)
    throw InputError("output folder '" + dir.string() + "' cannot be written: it cannot be created (" + made.message() +
                     ")");
  const std::filesystem::path lock = dir / ".contact3d.lock";
  lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd_ < 0) {
    const std::string why = std::strerror(errno);
    if (std::filesystem::exists(lock, ec))  // the folder may be writable, the lock another user's
      throw InputError("output folder '" + dir.string() + "' cannot be written: its lock file '" + lock.string() +
                       "' cannot be opened (" + why +
                       "; left by a solve of another user?): remove it, or choose another folder with --out");
    throw InputError("output folder '" + dir.string() + "' cannot be written: " + why);
  }
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw InputError("another contact3d solve is writing to '" + dir.string() +
                     "' right now; wait for it or choose another folder with --out");
  }
  try {  // a refusal from here on lets the lock go (the destructor does not run for a throwing constructor)
    clear_for_this_run(what);
  } catch (...) {
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw;
  }
}

// The previous run's files out, the RUNNING marker in (the lock is held).
void RunFolder::clear_for_this_run(const std::string& what) {
  const std::filesystem::path& dir = dir_;
  std::error_code ec;
  if (held_by_a_running_solve(dir / "steps"))
    throw InputError("another contact3d solve is writing to '" + (dir / "steps").string() +
                     "', where this one would write its steps; choose another folder with --out");
  for (const char* name : kRunOutputs) {
    std::filesystem::remove(dir / name, ec);
    std::filesystem::remove(dir / (std::string(name) + ".partial"), ec);  // a killed run's unfinished write
  }
  remove_run_report(dir);
  remove_step_files(dir);
  std::ofstream marker(dir / "RUNNING");
  marker << what << "\npid " << ::getpid() << "\n";
  if (!marker.flush()) throw InputError("output folder '" + dir.string() + "' cannot be written");
}

void RunFolder::finish(const std::string& not_converged) {
  if (!not_converged.empty())
    write_file(dir_ / "NOT_CONVERGED", [&](std::ostream& out) {
      out << "not converged: " << not_converged
          << "\nthe files hold the last iterate, not a solution (summary.json: converged = false)\n";
    });
  std::error_code ec;
  std::filesystem::remove(dir_ / "RUNNING", ec);
}

RunFolder::~RunFolder() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock; RUNNING stays when finish() was not reached
}

}  // namespace contact3d
