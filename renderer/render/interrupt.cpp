#include "renderer/render/interrupt.h"

#include <unistd.h>

#include <csignal>
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

extern "C" void on_signal(int sig) {
  // Loading, validating and building hold nothing worth keeping, and parsers (tinyobjloader) cannot
  // be asked to stop: end at once rather than make the user wait for a 17 s OBJ to finish loading.
  if (!g_keep_work.load()) exit_now(sig);
  int none = 0;
  g_signal.compare_exchange_strong(none, sig);
  g_interrupted.store(true);
  std::signal(sig, SIG_DFL);  // the same signal again ends the program at once
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
