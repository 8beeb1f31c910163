// Interruption: a signal asks the renderer to stop at the next tile, and the command writes what
// it has. SIGINT (Ctrl-C), SIGTERM (Slurm at a time limit or on pre-emption, `timeout`, systemd,
// container runtimes) and SIGHUP (a closed terminal) all mean "stop and keep the work". The flag
// lives in the renderer library, which reads it; main installs the handlers.
#pragma once
#include <atomic>

namespace pt {

// Set by the first SIGINT, SIGTERM or SIGHUP; the renderer stops at the next tile.
extern std::atomic<bool> g_interrupted;

// Installs the handlers (and ignores SIGXFSZ, so a write past `ulimit -f` fails with EFBIG instead
// of killing pt). A second signal, more than half a second after the first, ends the program at
// once ("nothing written"); one sooner is the same request (`timeout` sends its signal twice).
void install_interrupt_handlers();

// Until a command calls this with true, there is no work to keep: the first signal prints
// "pt: interrupted (SIG...); nothing written" and exits 128 + signal at once, even in the middle
// of loading a scene. With true, the signal sets g_interrupted and the command writes what it has.
void keep_work_on_interrupt(bool keep);

// The signal that set g_interrupted, or 0.
int interrupt_signal();
// The exit status for an interrupted command: 128 + the signal (130 for SIGINT, 143 for SIGTERM,
// 129 for SIGHUP), as shells report a process ended by it.
int interrupted_exit_code();
// "SIGINT", "SIGTERM" or "SIGHUP" (or "a signal").
const char* interrupt_signal_name();

}  // namespace pt
