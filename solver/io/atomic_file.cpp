#include "io/atomic_file.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>

#include "base/errors.hpp"

namespace contact3d {
namespace {

[[noreturn]] void fail(const std::filesystem::path& file, const std::filesystem::path& partial, int err) {
  std::error_code ec;
  std::filesystem::remove(partial, ec);
  throw InputError("cannot write '" + file.string() + "': " + (err ? std::strerror(err) : "write failed") +
                   " (is the disk full, the output folder writable, or a file-size limit set?)");
}

}  // namespace

void write_file(const std::filesystem::path& file, const std::function<void(std::ostream&)>& content) {
  const std::filesystem::path partial = file.string() + ".partial";
  std::ofstream out(partial, std::ios::binary | std::ios::trunc);
  if (!out) fail(file, partial, errno);
  out.precision(12);
  errno = 0;
  content(out);
  out.flush();
  if (!out) fail(file, partial, errno);
  out.close();
  if (out.fail()) fail(file, partial, errno);
  std::error_code ec;
  std::filesystem::rename(partial, file, ec);
  if (ec) fail(file, partial, ec.value());
}

}  // namespace contact3d
