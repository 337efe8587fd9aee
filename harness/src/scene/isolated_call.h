// Runs a piece of work in a forked child process with a deadline, so that a
// third-party library that asserts (abort), crashes or never returns on bad
// input can neither kill nor freeze raybench. The child writes its answer to
// a pipe; the parent reads it with poll() until the deadline, kills the child
// with SIGKILL when the deadline passes, and always reaps it with waitpid.
//
// The child is a fork of a process that may be running TBB worker threads:
// only the forking thread exists in it, so `work` must not use TBB or any
// lock another thread may have held at the fork (should a library it calls
// block on one, the deadline ends the child). It may allocate (glibc resets
// malloc's locks in the child of fork) and write(2) to its descriptor.
// The child ends with _exit: it never returns into the caller's code, runs no
// atexit handlers and flushes no stdio buffers inherited from the parent.
// `work` may call _exit(0) itself once it has written its answer, to skip
// freeing what it built (the parent waits for the child's exit).
// SIGINT and SIGTERM are reset to their defaults in the child, so a handler
// of the parent (which removes the parent's temporary files) never runs there.
// What the child prints on stdout or stderr (e.g. assimp's "ai_assert
// failure in ..." before it aborts) is captured, not shown: the caller gets
// its last line with a failure, and raybench's output stays one error line.
#pragma once

#include <chrono>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace raybench {

// The child gave no answer. kind says why; detail is the signal number
// (kSignal), the exit status (kExit) or 0 (kDeadline); said is the last
// non-empty line the child printed on stdout or stderr ("" if none).
class IsolatedCallFailed : public std::runtime_error {
 public:
  enum class Kind { kSignal, kExit, kDeadline };
  IsolatedCallFailed(Kind kind, int detail, std::string said = "");
  Kind kind() const { return kind_; }
  int detail() const { return detail_; }
  const std::string& said() const { return said_; }

 private:
  Kind kind_;
  int detail_;
  std::string said_;
};

// "SIGABRT", "SIGSEGV", ... (or "signal N" for one without a name).
std::string signal_name(int signal);

// Runs work(fd) in a child process and returns every byte it wrote to fd,
// once it has exited with status 0 (work returned) within `deadline`.
// Throws IsolatedCallFailed when the child was killed by a signal, exited
// with another status (an exception escaping work exits with 70), or was
// still running at the deadline (it is then killed). Throws std::system_error
// when no pipe or process can be created. The child is reaped in every case.
std::string run_isolated(const std::function<void(int fd)>& work, std::chrono::milliseconds deadline);

// The same, handing each chunk of what the child writes to `receive` as it
// arrives, so that a large answer is copied once, into where it belongs.
// Returns normally only when the child succeeded; otherwise what `receive`
// was given must be discarded. When `receive` throws, the child is killed
// and reaped and the exception propagates.
void run_isolated(const std::function<void(int fd)>& work, std::chrono::milliseconds deadline,
                  const std::function<void(std::string_view chunk)>& receive);

// Writes all of data to fd (a pipe), retrying short writes and EINTR; false
// on any other failure (e.g. the parent has gone). For use in `work`.
bool write_all(int fd, const void* data, std::size_t size);

}  // namespace raybench
