// Specification of isolated_call.h: work in a child process whose crash,
// failure or hang is reported, never suffered, and which is always reaped.
#include "scene/isolated_call.h"

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <stdexcept>

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

namespace raybench {
namespace {

using namespace std::chrono_literals;

// The failure run_isolated reports for `work`; fails the test if none.
IsolatedCallFailed failure_of(const std::function<void(int)>& work, std::chrono::milliseconds deadline = 10s) {
  try {
    run_isolated(work, deadline);
  } catch (const IsolatedCallFailed& e) {
    return e;
  }
  ADD_FAILURE() << "the call did not fail";
  return IsolatedCallFailed(IsolatedCallFailed::Kind::kExit, 0);
}

// No child of this process is left, running or as a zombie.
bool no_child_left() { return ::waitpid(-1, nullptr, WNOHANG) == -1 && errno == ECHILD; }

TEST(IsolatedCall, ReturnsEveryByteTheChildWrote) {
  const std::string big(3 << 20, 'x');  // larger than the pipe: the parent reads while the child writes
  const std::string got = run_isolated([&](int fd) { write_all(fd, big.data(), big.size()); }, 60s);
  EXPECT_EQ(got, big);
  EXPECT_EQ(run_isolated([](int) {}, 10s), "");
  EXPECT_TRUE(no_child_left());
}

TEST(IsolatedCall, AChildKilledByASignalIsReportedWithTheSignalsName) {
  const IsolatedCallFailed abort = failure_of([](int) { std::abort(); });
  EXPECT_EQ(abort.kind(), IsolatedCallFailed::Kind::kSignal);
  EXPECT_EQ(signal_name(abort.detail()), "SIGABRT");
  // Killed from outside (the OOM killer sends SIGKILL): a crash, not a missed
  // deadline. (SIGKILL, not SIGSEGV: AddressSanitizer turns a SIGSEGV into exit 1.)
  const IsolatedCallFailed killed = failure_of([](int) { ::raise(SIGKILL); });
  EXPECT_EQ(killed.kind(), IsolatedCallFailed::Kind::kSignal);
  EXPECT_EQ(signal_name(killed.detail()), "SIGKILL");
  EXPECT_TRUE(no_child_left());
}

TEST(IsolatedCall, AChildThatExitsNonZeroOrThrowsIsReportedWithItsStatus) {
  const IsolatedCallFailed exited = failure_of([](int fd) {
    write_all(fd, "partial", 7);
    ::_exit(3);
  });
  EXPECT_EQ(exited.kind(), IsolatedCallFailed::Kind::kExit);
  EXPECT_EQ(exited.detail(), 3);
  const IsolatedCallFailed threw = failure_of([](int) { throw std::runtime_error("no"); });
  EXPECT_EQ(threw.kind(), IsolatedCallFailed::Kind::kExit);
  EXPECT_EQ(threw.detail(), 70);
  EXPECT_TRUE(no_child_left());
}

// The caller decodes the answer as it streams; when it refuses it, the
// child (which would go on writing) is killed and reaped.
TEST(IsolatedCall, WhenTheReceiverThrowsTheChildIsKilledAndTheExceptionPropagates) {
  std::size_t received = 0;
  EXPECT_THROW(run_isolated(
                   [](int fd) {
                     const std::string block(1 << 16, 'x');
                     for (;;) write_all(fd, block.data(), block.size());
                   },
                   10s,
                   [&](std::string_view chunk) {
                     received += chunk.size();
                     throw std::length_error("more than announced");
                   }),
               std::length_error);
  EXPECT_GT(received, 0u);
  EXPECT_TRUE(no_child_left());
}

// A library's last words (assimp prints its failed assertion, then aborts)
// come with the failure instead of on raybench's stderr.
TEST(IsolatedCall, WhatTheChildPrintsIsCapturedAndItsLastLineReported) {
  const IsolatedCallFailed e = failure_of([](int) {
    const std::string out = "progress\n", err = "ai_assert failure in X.cpp(238): numOut != n\n\n";
    write_all(STDOUT_FILENO, out.data(), out.size());
    write_all(STDERR_FILENO, err.data(), err.size());
    std::abort();
  });
  EXPECT_EQ(e.said(), "ai_assert failure in X.cpp(238): numOut != n");
  EXPECT_EQ(failure_of([](int) { ::_exit(1); }).said(), "");
}

// The kill path: a child that never ends, with or without its pipe open.
TEST(IsolatedCall, AChildStillRunningAtTheDeadlineIsKilledAndReaped) {
  const IsolatedCallFailed blocked = failure_of([](int) { for (;;) ::pause(); }, 50ms);
  EXPECT_EQ(blocked.kind(), IsolatedCallFailed::Kind::kDeadline);
  EXPECT_TRUE(no_child_left());
  const IsolatedCallFailed closed = failure_of(
      [](int fd) {
        ::close(fd);
        for (;;) ::pause();
      },
      50ms);
  EXPECT_EQ(closed.kind(), IsolatedCallFailed::Kind::kDeadline);
  EXPECT_TRUE(no_child_left());
}

}  // namespace
}  // namespace raybench
