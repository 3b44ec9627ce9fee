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
  if (lock_fd_ < 0) throw InputError("output folder '" + dir.string() + "' cannot be written: " + std::strerror(errno));
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw InputError("another contact3d solve is writing to '" + dir.string() +
                     "' right now; wait for it or choose another folder with --out");
  }
  for (const char* name : kRunOutputs) {
    std::filesystem::remove(dir / name, ec);
    std::filesystem::remove(dir / (std::string(name) + ".partial"), ec);  // a killed run's unfinished write
  }
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
