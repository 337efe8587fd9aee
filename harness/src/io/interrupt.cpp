// The SIGINT/SIGTERM handler that removes half-written results
// (io/interrupt.h): fixed storage for the paths (the handler may not
// allocate), async-signal-safe calls only.
#include "io/interrupt.h"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <iostream>
#include <pthread.h>
#include <stdexcept>
#include <unistd.h>

namespace raybench {
namespace {

// Fixed storage: the handler may not allocate. 4096 is Linux's PATH_MAX; a
// longer path cannot be opened, so it never needs removing.
constexpr int kSlots = 16;
constexpr std::size_t kPathBytes = 4096;

struct Slot {
  std::atomic<bool> claimed{false};    // owned by a RemoveOnInterrupt
  std::atomic<bool> published{false};  // `path` is complete: the handler may read it
  char path[kPathBytes];
};
Slot g_slots[kSlots];

// Two message buffers: the main thread fills the one the handler does not
// read, then switches, so a signal in the middle of set_interrupt_message
// (on the same thread) still finds a whole line.
struct Message {
  char text[2 * kPathBytes + 512];
  std::size_t size = 0;
};
Message g_messages[2];
std::atomic<int> g_current{0};

pthread_t g_main_thread;
pid_t g_process = 0;  // the process that installed the handler
std::atomic<bool> g_installed{false};

static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free,
              "the handler reads these atomics: they must be lock-free to be async-signal-safe");

void write_all(const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(STDERR_FILENO, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    data += n;
    size -= static_cast<std::size_t>(n);
  }
}

void write_text(const char* s) { write_all(s, std::strlen(s)); }

extern "C" void on_interrupt(int signal) {
  // A child forked by this process (e.g. to isolate a loader) inherits the
  // handler but owns none of the files and is not the one to report.
  if (::getpid() != g_process) ::_exit(128 + signal);
  if (!pthread_equal(pthread_self(), g_main_thread)) {
    // Another thread (a TBB worker, Embree's) caught it: the main thread does
    // the work, after any section it deferred signals for.
    const int saved = errno;
    pthread_kill(g_main_thread, signal);
    errno = saved;
    return;
  }
  for (Slot& slot : g_slots)
    if (slot.published.load(std::memory_order_acquire)) ::unlink(slot.path);
  write_text(signal == SIGINT ? "raybench: interrupted by SIGINT: " : "raybench: interrupted by SIGTERM: ");
  const Message& m = g_messages[g_current.load(std::memory_order_acquire)];
  write_all(m.text, m.size);
  write_text("\n");
  ::_exit(128 + signal);
}

void set_signal_mask(int how, sigset_t* old) {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(how, &set, old);
}

}  // namespace

void install_interrupt_handler() {
  if (g_installed.exchange(true)) return;
  g_main_thread = pthread_self();
  g_process = ::getpid();
  set_interrupt_message("no results written");
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  sigaddset(&action.sa_mask, SIGINT);
  sigaddset(&action.sa_mask, SIGTERM);
  action.sa_flags = SA_RESTART;  // a forwarding worker's interrupted call resumes
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

void set_interrupt_message(const std::string& line) {
  const int next = 1 - g_current.load(std::memory_order_relaxed);
  Message& m = g_messages[next];
  m.size = std::min(line.size(), sizeof m.text);
  std::memcpy(m.text, line.data(), m.size);
  g_current.store(next, std::memory_order_release);
}

void print_stderr_line(const std::string& line) {
  const std::string whole = line + '\n';
  const SignalsDeferred deferred;
  std::cerr.flush();
  write_all(whole.data(), whole.size());
}

RemoveOnInterrupt::RemoveOnInterrupt(const std::string& path) : slot_(-1) {
  if (path.size() >= kPathBytes) return;  // cannot be created either
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (g_slots[i].claimed.compare_exchange_strong(expected, true)) {
      std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
      g_slots[i].published.store(true, std::memory_order_release);
      slot_ = i;
      return;
    }
  }
  throw std::logic_error("RemoveOnInterrupt: more than 16 files registered at once");
}

RemoveOnInterrupt::~RemoveOnInterrupt() {
  if (slot_ < 0) return;
  g_slots[slot_].published.store(false, std::memory_order_release);
  g_slots[slot_].claimed.store(false, std::memory_order_release);
}

SignalsDeferred::SignalsDeferred() { set_signal_mask(SIG_BLOCK, &old_); }

SignalsDeferred::~SignalsDeferred() { pthread_sigmask(SIG_SETMASK, &old_, nullptr); }

}  // namespace raybench
