// Every file raybench reads or writes goes through these checks at the
// boundary, so that a FIFO, a directory or a device given where a file is
// expected is refused with one line naming it (a FIFO would block forever
// on open, a device would be read or replaced), before anything is opened.
#pragma once

#include <string>

namespace raybench {

// Throws InputError naming `path` unless it is an existing regular file (or a
// symbolic link to one). `what` says what was expected, e.g. "ray file".
void check_input_file(const std::string& path, const std::string& what);

// Throws InputError naming `path` when it exists and is not a regular file
// (a directory, FIFO, socket or device): results are only ever written to
// regular files, replaced atomically.
void check_output_file(const std::string& path);

}  // namespace raybench
