// write_file: an output file appears under its name only once it is completely written. The
// content goes to "<name>.partial" in the same folder, the stream is flushed and checked, closed
// and renamed into place; on any failure (full disk, a file-size limit, an unwritable folder) the
// partial file is removed and an InputError names the file and the reason.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>

namespace contact3d {

void write_file(const std::filesystem::path& file, const std::function<void(std::ostream&)>& content);

// For the handler of a stopping signal (SIGTERM, SIGINT, SIGHUP): removes the ".partial" file being
// written at that moment, if any, so that a run stopped while writing its results leaves none behind
// (a helper's SIGTERM left body.vtu.partial). Async-signal-safe: unlink of a path held for it. The one
// piece of process-wide state in the io layer, as signals are the process's.
void remove_partial_file_for_signal() noexcept;

}  // namespace contact3d
