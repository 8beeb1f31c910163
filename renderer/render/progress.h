// Progress on stderr: a bar redrawn in place on a terminal, or a quiet line per pass (at most one
// every few seconds) when stderr is a file or a pipe.
#pragma once
#include <cstdint>
#include <string>

namespace pt {

class Progress {
 public:
  explicit Progress(bool quiet);
  void update(int done, int total, double seconds, uint64_t rays, double time_budget);
  // A resumed render starts with `done` passes already in the film: the ETA counts only this run's.
  void start_at(int done) { first_ = done; }
  void finish();

 private:
  bool quiet_;
  bool tty_;
  double last_print_ = -1e9;
  bool drawn_ = false;
  int first_ = 0;
};

std::string format_seconds(double s);

}  // namespace pt
