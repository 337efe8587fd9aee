#include "scene/isolated_call.h"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <exception>
#include <system_error>
#include <vector>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

namespace raybench {
namespace {

using Clock = std::chrono::steady_clock;

// Of what the child printed, only this much of the end is kept.
constexpr std::size_t kSaidBytes = 4096;

std::string describe(IsolatedCallFailed::Kind kind, int detail) {
  switch (kind) {
    case IsolatedCallFailed::Kind::kSignal: return "killed by " + signal_name(detail);
    case IsolatedCallFailed::Kind::kExit: return "exited with status " + std::to_string(detail);
    case IsolatedCallFailed::Kind::kDeadline: break;
  }
  return "did not finish before its deadline";
}

// The last non-empty line of `text`, control characters made spaces.
std::string last_line(const std::string& text) {
  const std::size_t end = text.find_last_not_of("\r\n\t ");
  if (end == std::string::npos) return "";
  const std::size_t newline = text.find_last_of("\r\n", end);
  const std::size_t start = newline == std::string::npos ? 0 : newline + 1;
  std::string line = text.substr(start, end + 1 - start);
  for (char& c : line)
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  return line;
}

// A descriptor, closed once: at scope end or by reset().
struct Fd {
  int fd = -1;
  ~Fd() { reset(); }
  void reset() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
};

void make_pipe(Fd& read_end, Fd& write_end) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::system_error(errno, std::generic_category(), "pipe");
  read_end.fd = fds[0];
  write_end.fd = fds[1];
}

// Milliseconds left until `end` for poll(), rounded up so that a poll never
// returns just before the deadline and spins; 0 once it has passed.
int poll_timeout(Clock::time_point end) {
  const auto left = std::chrono::ceil<std::chrono::milliseconds>(end - Clock::now()).count();
  return static_cast<int>(std::clamp<decltype(left)>(left, 0, INT_MAX));
}

// Waits for the child to end, killing it at `end`; true when it was killed
// for the deadline. Returns its wait status in `status`.
bool reap(pid_t pid, Clock::time_point end, int& status) {
  // The child closes its pipes as it exits, so it is normally ending
  // already. A pidfd becomes readable when it has ended (Linux 5.3); where
  // there is none, the child is polled every ms. Either way, one that closed
  // its pipes and went on is killed at the deadline.
  // The raw system call: glibc 2.36's <sys/pidfd.h> lacks extern "C".
  Fd pidfd{static_cast<int>(::syscall(SYS_pidfd_open, pid, 0))};
  for (;;) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) return false;
    if (r < 0 && errno != EINTR) {
      status = 0;  // not our child any more (only if SIGCHLD were ignored): nothing to reap
      return false;
    }
    const int timeout = poll_timeout(end);
    if (timeout == 0) break;
    if (pidfd.fd >= 0) {
      pollfd p{pidfd.fd, POLLIN, 0};
      ::poll(&p, 1, timeout);
    } else {
      const timespec ms{0, 1'000'000};
      ::nanosleep(&ms, nullptr);
    }
  }
  ::kill(pid, SIGKILL);
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return true;
}

}  // namespace

IsolatedCallFailed::IsolatedCallFailed(Kind kind, int detail, std::string said)
    : std::runtime_error(describe(kind, detail)), kind_(kind), detail_(detail), said_(std::move(said)) {}

std::string signal_name(int signal) {
  if (const char* abbrev = ::sigabbrev_np(signal)) return std::string("SIG") + abbrev;
  return "signal " + std::to_string(signal);
}

bool write_all(int fd, const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

void run_isolated(const std::function<void(int fd)>& work, std::chrono::milliseconds deadline,
                  const std::function<void(std::string_view chunk)>& receive) {
  Fd answer_in, answer_out, said_in, said_out;
  make_pipe(answer_in, answer_out);
  make_pipe(said_in, said_out);
  // A larger pipe (up to the unprivileged limit, 1 MiB by default) means
  // fewer wake-ups while a large mesh streams through; best effort.
  ::fcntl(answer_out.fd, F_SETPIPE_SZ, 1 << 20);

  const Clock::time_point end = Clock::now() + deadline;
  const pid_t pid = ::fork();
  if (pid < 0) throw std::system_error(errno, std::generic_category(), "fork");
  if (pid == 0) {
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    ::signal(SIGPIPE, SIG_DFL);
    // dup2 clears O_CLOEXEC on the copies; the originals close at _exit.
    ::dup2(said_out.fd, STDOUT_FILENO);
    ::dup2(said_out.fd, STDERR_FILENO);
    int status = 0;
    try {
      work(answer_out.fd);
    } catch (...) {
      status = 70;  // EX_SOFTWARE
    }
    ::_exit(status);
  }
  // The child holds the only write ends: each pipe reads EOF when it exits.
  answer_out.reset();
  said_out.reset();

  std::string said;
  bool timed_out = false;
  std::exception_ptr receive_failed;
  // Reads as large as the pipe: a mesh's megabytes in few wake-ups.
  std::vector<char> chunk(1 << 20);
  while ((answer_in.fd >= 0 || said_in.fd >= 0) && !receive_failed) {
    const int timeout = poll_timeout(end);
    if (timeout == 0) {
      timed_out = true;
      break;
    }
    pollfd p[2] = {{answer_in.fd, POLLIN, 0}, {said_in.fd, POLLIN, 0}};  // poll skips a negative fd
    const int ready = ::poll(p, 2, timeout);
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0) break;  // cannot happen with valid descriptors; the exit status decides
    for (int i = 0; i < 2; ++i) {
      if (p[i].fd < 0 || p[i].revents == 0) continue;
      Fd& from = i == 0 ? answer_in : said_in;
      const ssize_t n = ::read(from.fd, chunk.data(), chunk.size());
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        from.reset();  // EOF: the child has exited or closed its end
        continue;
      }
      if (i == 0) {
        try {
          receive(std::string_view(chunk.data(), static_cast<std::size_t>(n)));
        } catch (...) {
          receive_failed = std::current_exception();
          break;
        }
        continue;
      }
      said.append(chunk.data(), static_cast<std::size_t>(n));
      if (said.size() > 2 * kSaidBytes) said.erase(0, said.size() - kSaidBytes);
    }
  }
  answer_in.reset();
  said_in.reset();

  int status = 0;
  if (timed_out || receive_failed) {
    ::kill(pid, SIGKILL);
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  } else {
    timed_out = reap(pid, end, status);
  }
  if (receive_failed) std::rethrow_exception(receive_failed);
  // A child that ended by itself (or crashed) just before the deadline is
  // reported as it ended, not as a timeout: only SIGKILL, ours, means that.
  if (WIFSIGNALED(status) && !(timed_out && WTERMSIG(status) == SIGKILL))
    throw IsolatedCallFailed(IsolatedCallFailed::Kind::kSignal, WTERMSIG(status), last_line(said));
  if (timed_out) throw IsolatedCallFailed(IsolatedCallFailed::Kind::kDeadline, 0, last_line(said));
  if (WIFEXITED(status) && WEXITSTATUS(status) != 0)
    throw IsolatedCallFailed(IsolatedCallFailed::Kind::kExit, WEXITSTATUS(status), last_line(said));
}

std::string run_isolated(const std::function<void(int fd)>& work, std::chrono::milliseconds deadline) {
  std::string answer;
  run_isolated(work, deadline, [&](std::string_view chunk) { answer.append(chunk); });
  return answer;
}

}  // namespace raybench
