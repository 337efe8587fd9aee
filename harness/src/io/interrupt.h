// SIGINT and SIGTERM while a command writes results: the temporary files being
// written are removed, one line saying where the results are (or that there
// are none) goes to stderr, and the process ends with 128 + the signal number
// (130 for SIGINT, 143 for SIGTERM), as a shell reports a process killed by
// it. Finished results are already on disk (suite_run.cpp writes them after
// every scene); the handler only removes what is half-written.
//
// Guarantee: the handler calls only async-signal-safe functions (unlink,
// write, getpid, pthread_kill, pthread_self, _exit). In a child process
// forked from this one it only exits, 128 + the signal. It does its work on the thread
// that installed it (the main thread, the only one that writes result files):
// on another thread it forwards the signal there. So a file is never half
// removed while that thread is creating it, and a section that blocks the
// signals on the main thread (SignalsDeferred) completes before the handler
// runs.
#pragma once

#include <csignal>
#include <string>

namespace raybench {

// Installs the handler for SIGINT and SIGTERM; call it on the main thread
// before a command that writes results starts its work. Without it, the
// signals keep their default action (the registry below is then unused).
void install_interrupt_handler();

// The line the handler prints (a newline is added), e.g. "partial results
// (1 of 3 scenes) in out.csv". Formatted here, before any signal, since the
// handler cannot format. Call it on the main thread.
void set_interrupt_message(const std::string& line);

// Writes `line` and a newline to stderr in one piece, with SIGINT and SIGTERM
// deferred meanwhile: the handler's own line then always starts a line of its
// own, never the tail of a status line cut in two (std::cerr writes each `<<`
// separately). Every status and error line of raybench goes through it.
void print_stderr_line(const std::string& line);

// A file to remove if a signal ends the process while this object lives:
// a temporary file being written, or a probe. Registering does not create
// the file and unregistering does not remove it. At most 16 at once.
class RemoveOnInterrupt {
 public:
  explicit RemoveOnInterrupt(const std::string& path);
  ~RemoveOnInterrupt();
  RemoveOnInterrupt(const RemoveOnInterrupt&) = delete;
  RemoveOnInterrupt& operator=(const RemoveOnInterrupt&) = delete;

 private:
  int slot_;
};

// Blocks SIGINT and SIGTERM on the calling thread while it lives, so that a
// group of writes that belong together (a results CSV and its metadata)
// happens whole or not at all; a signal that arrives meanwhile is handled
// when this object ends.
class SignalsDeferred {
 public:
  SignalsDeferred();
  ~SignalsDeferred();
  SignalsDeferred(const SignalsDeferred&) = delete;
  SignalsDeferred& operator=(const SignalsDeferred&) = delete;

 private:
  sigset_t old_;
};

}  // namespace raybench
