// Specification of io/interrupt.h's stderr guarantee: whenever SIGINT or
// SIGTERM ends a run that is printing status lines, stderr ends with the
// handler's line, whole and on a line of its own, and every line before it is
// a whole status line. Scripts take the last line of stderr to find the
// partial results.
#include "io/interrupt.h"

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <random>
#include <sstream>
#include <string>
#include <stdexcept>

#include <gtest/gtest.h>

namespace raybench {
namespace {

// A child process that installs the handler and prints status lines to a pipe
// until a signal ends it. Returns its stderr and its exit code.
struct Ended {
  std::string stderr_text;
  int exit_code = -1;
};

Ended print_until_signalled(int signal, std::chrono::microseconds delay) {
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error("pipe failed");
  const pid_t child = ::fork();
  if (child == 0) {
    ::dup2(fds[1], STDERR_FILENO);
    ::close(fds[0]);
    ::close(fds[1]);
    install_interrupt_handler();
    set_interrupt_message("partial results (1 of 3 scenes) in out.csv");
    for (long i = 0;; ++i) print_stderr_line("raybench: scene " + std::to_string(i) + ": tracing");
  }
  ::close(fds[1]);
  std::string text;
  char buffer[4096];
  // Wait for the first line, then signal after `delay` while the child prints.
  bool signalled = false;
  const auto first = std::chrono::steady_clock::now();
  for (;;) {
    pollfd p{fds[0], POLLIN, 0};
    ::poll(&p, 1, 10);
    if (p.revents & (POLLIN | POLLHUP)) {
      const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
      if (n <= 0) break;
      text.append(buffer, static_cast<std::size_t>(n));
    }
    if (!signalled && !text.empty() && std::chrono::steady_clock::now() - first >= delay) {
      ::kill(child, signal);
      signalled = true;
    }
  }
  ::close(fds[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  return {text, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

void expect_whole_lines_ending_with(const Ended& ended, const std::string& last) {
  ASSERT_FALSE(ended.stderr_text.empty());
  ASSERT_EQ(ended.stderr_text.back(), '\n');
  std::istringstream lines(ended.stderr_text);
  std::string line, previous;
  while (std::getline(lines, line)) {
    if (!previous.empty()) {
      EXPECT_EQ(previous.rfind("raybench: scene ", 0), 0u) << previous;
      EXPECT_EQ(previous.substr(previous.size() - 9), ": tracing") << previous;
    }
    previous = line;
  }
  EXPECT_EQ(previous, last);
}

TEST(InterruptHandler, EndsStderrWithItsOwnWholeLineWhateverStatusLineWasBeingPrinted) {
  // Signals at many moments of the printing loop: one of them lands between
  // the pieces of a status line, if a line is ever written in pieces.
  std::mt19937 random(7);
  for (int round = 0; round < 60; ++round) {
    const int signal = round % 2 ? SIGINT : SIGTERM;
    const Ended ended = print_until_signalled(signal, std::chrono::microseconds(random() % 3000));
    EXPECT_EQ(ended.exit_code, 128 + signal);
    expect_whole_lines_ending_with(ended, std::string("raybench: interrupted by ") +
                                              (signal == SIGINT ? "SIGINT" : "SIGTERM") +
                                              ": partial results (1 of 3 scenes) in out.csv");
    if (HasFailure()) break;
  }
}

}  // namespace
}  // namespace raybench
