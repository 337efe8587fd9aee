#include "io/atomic_file.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <unistd.h>

#include "io/error.h"
#include "io/interrupt.h"

namespace raybench {

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write,
                           std::ios::openmode mode) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path() && !fs::exists(target.parent_path(), ec)) {
    fs::create_directories(target.parent_path(), ec);
    if (ec) throw InputError(path, "cannot create directory " + target.parent_path().string() + ": " + ec.message());
  }
  if (fs::is_directory(target, ec)) throw InputError(path, "is a directory");
  const std::string temp = path + ".tmp." + std::to_string(::getpid());
  const RemoveOnInterrupt remove_temp(temp);  // registered before it exists, until it is renamed or removed
  {
    std::ofstream out(temp, mode | std::ios::trunc);
    if (!out) throw InputError(path, std::string("cannot be written: ") + std::strerror(errno));
    try {
      write(out);
    } catch (...) {
      out.close();
      fs::remove(temp, ec);
      throw;
    }
    out.flush();
    if (!out) {
      out.close();
      fs::remove(temp, ec);
      throw InputError(path, "write failed (disk full?)");
    }
  }
  fs::rename(temp, target, ec);
  if (ec) {
    fs::remove(temp, ec);
    throw InputError(path, "cannot be replaced: " + ec.message());
  }
}

TemporaryFile::TemporaryFile(std::string path)
    : path_(std::move(path)), on_interrupt_(std::make_unique<RemoveOnInterrupt>(path_)) {}

TemporaryFile::~TemporaryFile() {
  std::error_code ec;
  if (on_interrupt_) std::filesystem::remove(path_, ec);
}

void TemporaryFile::keep_as(const std::string& target) {
  std::error_code ec;
  std::filesystem::rename(path_, target, ec);
  if (ec) throw InputError(target, "cannot be replaced: " + ec.message());
  on_interrupt_.reset();
}

void check_writable(const std::string& path) {
  std::error_code ec;
  const std::string probe = path + ".probe." + std::to_string(::getpid());
  const RemoveOnInterrupt remove_probe(probe);
  try {
    write_file_atomically(probe, [](std::ostream&) {});
  } catch (const InputError& e) {  // named after the probe: name the user's path
    throw InputError(path, std::string(e.what()).substr(probe.size() + 2));
  }
  std::filesystem::remove(probe, ec);
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a directory");
}

}  // namespace raybench
