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

}  // namespace contact3d
