#include "io/input_file.h"

#include <filesystem>

#include "io/error.h"

namespace raybench {
namespace {

// "a FIFO", "a directory", ... for the message; empty for a regular file.
std::string not_regular(const std::filesystem::file_status& s) {
  namespace fs = std::filesystem;
  switch (s.type()) {
    case fs::file_type::regular: return "";
    case fs::file_type::directory: return "a directory";
    case fs::file_type::fifo: return "a FIFO (named pipe)";
    case fs::file_type::socket: return "a socket";
    case fs::file_type::block: return "a block device";
    case fs::file_type::character: return "a character device";
    default: return "not a regular file";
  }
}

}  // namespace

void check_input_file(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status s = fs::status(path, ec);  // follows symbolic links
  if (s.type() == fs::file_type::not_found || s.type() == fs::file_type::none)
    throw InputError(path, "no such file (expected a " + what + ")");
  if (ec) throw InputError(path, "cannot be read: " + ec.message());
  if (const std::string kind = not_regular(s); !kind.empty())
    throw InputError(path, "is " + kind + ", expected a " + what + " (a regular file)");
}

void check_output_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status s = fs::status(path, ec);
  if (s.type() == fs::file_type::not_found || s.type() == fs::file_type::none) return;
  if (const std::string kind = not_regular(s); !kind.empty())
    throw InputError(path, "is " + kind + "; results are written only to regular files");
}

}  // namespace raybench
