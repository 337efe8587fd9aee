// Results are written to a temporary file beside the target and renamed into
// place only when complete, so a failure never leaves a half-written result.
#pragma once

#include <fstream>
#include <functional>
#include <memory>
#include <string>

#include "io/interrupt.h"

namespace raybench {

// Calls write(stream) on a temporary file, then renames it to `path`. The
// temporary file (`path`.tmp.PID) is removed on failure, and by the interrupt
// handler (interrupt.h) if a signal ends the process meanwhile.
// Throws InputError (naming `path`) when the file cannot be created or written.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write,
                           std::ios::openmode mode = std::ios::out);

// A temporary file that another writer (e.g. Google Benchmark's JSON output)
// fills: removed when this object ends unless keep_as() renamed it into
// place, and removed by the interrupt handler (interrupt.h) if a signal ends
// the process meanwhile. So no error path leaves it behind.
class TemporaryFile {
 public:
  explicit TemporaryFile(std::string path);
  ~TemporaryFile();
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;

  const std::string& path() const { return path_; }
  // Renames the file to `target`; throws InputError naming `target`.
  void keep_as(const std::string& target);

 private:
  std::string path_;
  std::unique_ptr<RemoveOnInterrupt> on_interrupt_;
};

// Checks, before a long run, that `path` could be written later: its folder
// exists (or is created) and accepts a file. Throws InputError naming `path`.
void check_writable(const std::string& path);

}  // namespace raybench
