// What a shell command prints, for the metadata a run records (git state,
// the Debian package a library comes from). Never throws: a command that
// cannot run prints nothing.
#pragma once

#include <string>

namespace raybench {

// Everything `command` writes to stdout, trailing newlines and spaces
// removed; "" when it cannot run.
std::string command_output(const std::string& command);

// Its first line only.
std::string command_first_line(const std::string& command);

}  // namespace raybench
