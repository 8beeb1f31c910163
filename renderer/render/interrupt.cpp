#include "renderer/render/interrupt.h"

#include <time.h>
#include <unistd.h>

#include <csignal>
#include <cstdint>
#include <cstring>

namespace pt {

std::atomic<bool> g_interrupted{false};

namespace {
std::atomic<int> g_signal{0};
std::atomic<bool> g_keep_work{false};

// Only async-signal-safe calls here: write(2) and _exit(2).
void exit_now(int sig) {
  const char* text = sig == SIGINT    ? "pt: interrupted (SIGINT); nothing written\n"
                     : sig == SIGTERM ? "pt: interrupted (SIGTERM); nothing written\n"
                                      : "pt: interrupted (SIGHUP); nothing written\n";
  ssize_t ignored = ::write(STDERR_FILENO, text, std::strlen(text));
  (void)ignored;
  ::_exit(128 + sig);
}

// CLOCK_MONOTONIC in nanoseconds (clock_gettime is async-signal-safe).
int64_t now_ns() {
  timespec t{};
  ::clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<int64_t>(t.tv_sec) * 1000000000 + t.tv_nsec;
}
std::atomic<int64_t> g_first_ns{0};
// A second signal within this time of the first is the same request: `timeout` signals pt and then
// its process group, so pt may get SIGTERM twice within microseconds. Ending at once on that one
// (the handler used to reset itself to the default action) lost the image the first was writing.
constexpr int64_t kRepeatNs = 500000000;

extern "C" void on_signal(int sig) {
  // Loading, validating and building hold nothing worth keeping, and parsers (tinyobjloader) cannot
  // be asked to stop: end at once rather than make the user wait for a 17 s OBJ to finish loading.
  if (!g_keep_work.load()) exit_now(sig);
  const int64_t now = now_ns();
  // The first signal's time, set before the signal is: a handler of another signal running in
  // between must not read a first time of 0.
  int64_t unset = 0;
  g_first_ns.compare_exchange_strong(unset, now);
  int none = 0;
  if (g_signal.compare_exchange_strong(none, sig)) {
    g_interrupted.store(true);
    return;
  }
  // A signal again, later: the user insists; end at once.
  if (now - g_first_ns.load() > kRepeatNs) exit_now(sig);
}
}  // namespace

void install_interrupt_handlers() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, on_signal);
  // `ulimit -f` sends SIGXFSZ on a write past the limit, whose default action kills pt mid-write;
  // ignored, the write fails with EFBIG and OutputFile reports it like a full disk.
  std::signal(SIGXFSZ, SIG_IGN);
}

void keep_work_on_interrupt(bool keep) { g_keep_work.store(keep); }

int interrupt_signal() { return g_signal.load(); }

int interrupted_exit_code() {
  int sig = g_signal.load();
  return 128 + (sig != 0 ? sig : SIGINT);
}

const char* interrupt_signal_name() {
  switch (g_signal.load()) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
  }
  return "a signal";
}

}  // namespace pt
