#include "renderer/interrupt.h"

#include <csignal>

namespace pt {

std::atomic<bool> g_interrupted{false};

namespace {
std::atomic<int> g_signal{0};

extern "C" void on_signal(int sig) {
  int none = 0;
  g_signal.compare_exchange_strong(none, sig);
  g_interrupted.store(true);
  std::signal(sig, SIG_DFL);  // the same signal again ends the program at once
}
}  // namespace

void install_interrupt_handlers() {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, on_signal);
}

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
