#include "io/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>

#include "base/errors.hpp"

namespace contact3d {
namespace {

// The partial file being written, for remove_partial_file_for_signal: its path copied in while
// `partial_held` is false, then published; cleared before the file is renamed or removed.
char partial_being_written[4096];
std::atomic<bool> partial_held{false};
static_assert(std::atomic<bool>::is_always_lock_free);

// Publishes `partial` for a signal handler while it lives.
class PartialForSignal {
 public:
  explicit PartialForSignal(const std::filesystem::path& partial) {
    const std::string& text = partial.native();
    if (text.size() >= sizeof partial_being_written) return;  // not held: a stop may leave it
    std::memcpy(partial_being_written, text.c_str(), text.size() + 1);
    partial_held.store(true);
  }
  ~PartialForSignal() { partial_held.store(false); }
  PartialForSignal(const PartialForSignal&) = delete;
  PartialForSignal& operator=(const PartialForSignal&) = delete;
};

[[noreturn]] void fail(const std::filesystem::path& file, const std::filesystem::path& partial, int err) {
  std::error_code ec;
  std::filesystem::remove(partial, ec);
  throw InputError("cannot write '" + file.string() + "': " + (err ? std::strerror(err) : "write failed") +
                   " (is the disk full, the output folder writable, or a file-size limit set?)");
}

}  // namespace

void write_file(const std::filesystem::path& file, const std::function<void(std::ostream&)>& content) {
  const std::filesystem::path partial = file.string() + ".partial";
  const PartialForSignal held(partial);
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

void remove_partial_file_for_signal() noexcept {
  if (partial_held.load()) ::unlink(partial_being_written);
}

}  // namespace contact3d
