#include "renderer/render/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace pt {

std::string format_seconds(double s) {
  char buf[32];
  if (s < 60) std::snprintf(buf, sizeof buf, "%.1f s", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%dm%02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  else std::snprintf(buf, sizeof buf, "%dh%02dm", static_cast<int>(s) / 3600, (static_cast<int>(s) / 60) % 60);
  return buf;
}

Progress::Progress(bool quiet) : quiet_(quiet), tty_(::isatty(STDERR_FILENO) != 0) {}

void Progress::update(int done, int total, double seconds, uint64_t rays, double time_budget) {
  if (quiet_) return;
  double mrays = seconds > 0 ? rays / seconds * 1e-6 : 0.0;
  double eta = done > first_ ? seconds / (done - first_) * (total - done) : 0.0;
  if (time_budget > 0) eta = std::min(eta, std::max(0.0, time_budget - seconds));
  if (tty_) {
    constexpr int kWidth = 30;
    int filled = total > 0 ? kWidth * done / total : kWidth;
    std::string bar(filled, '=');
    bar.resize(kWidth, ' ');
    std::fprintf(stderr, "\r  [%s] %d/%d spp  %.1f Mrays/s  ETA %s   ", bar.c_str(), done, total, mrays,
                 format_seconds(eta).c_str());
    std::fflush(stderr);
    drawn_ = true;
    return;
  }
  if (seconds - last_print_ < 5.0 && done != total) return;
  last_print_ = seconds;
  std::fprintf(stderr, "pt: pass %d/%d, %.1f Mrays/s, %s elapsed, ETA %s\n", done, total, mrays,
               format_seconds(seconds).c_str(), format_seconds(eta).c_str());
}

void Progress::finish() {
  if (drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace pt
