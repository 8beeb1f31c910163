// `pt bench rays`: not written yet (its issue is open); registers nothing.
#include "renderer/bench/bench.h"

namespace pt {

void add_bench_rays(CLI::App&, Action&) {}

}  // namespace pt
