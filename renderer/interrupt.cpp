#include "renderer/interrupt.h"

#include <csignal>

namespace pt {

std::atomic<bool> g_interrupted{false};

namespace {
extern "C" void on_sigint(int) {
  g_interrupted.store(true);
  std::signal(SIGINT, SIG_DFL);  // a second Ctrl-C ends the program at once
}
}  // namespace

void install_interrupt_handlers() { std::signal(SIGINT, on_sigint); }

}  // namespace pt
