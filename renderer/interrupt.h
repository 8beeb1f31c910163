// Interruption: a signal asks the renderer to stop at the next tile, and the command writes what
// it has. The flag lives in the renderer library, which reads it; main installs the handler.
#pragma once
#include <atomic>

namespace pt {

// Set by SIGINT; the renderer stops at the next tile and the partial image is written.
extern std::atomic<bool> g_interrupted;

// Installs the SIGINT handler that sets g_interrupted (a second Ctrl-C ends the program at once).
void install_interrupt_handlers();

}  // namespace pt
