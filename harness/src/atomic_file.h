// Results are written to a temporary file beside the target and renamed into
// place only when complete, so a failure never leaves a half-written result.
#pragma once

#include <fstream>
#include <functional>
#include <string>

namespace raybench {

// Calls write(stream) on a temporary file, then renames it to `path`.
// Throws InputError (naming `path`) when the file cannot be created or written.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write,
                           std::ios::openmode mode = std::ios::out);

// Checks, before a long run, that `path` could be written later: its folder
// exists (or is created) and accepts a file. Throws InputError naming `path`.
void check_writable(const std::string& path);

}  // namespace raybench
