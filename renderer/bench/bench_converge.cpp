// `pt bench converge`: not written yet (its issue is open); registers nothing.
#include "renderer/bench/bench.h"

namespace pt {

void add_bench_converge(CLI::App&, Action&) {}

}  // namespace pt
