// `pt bench`: measurements of speed and accuracy, each a subcommand in its own file.
#include "renderer/bench/bench.h"

namespace pt {

void add_bench_command(CLI::App& app, Action& action) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks: rays (backend speed), converge (error vs time), stability, lights (light samplers)");
  bench->require_subcommand(1);
  add_bench_rays(*bench, action);
  add_bench_converge(*bench, action);
  add_bench_stability(*bench, action);
  add_bench_lights(*bench, action);
}

}  // namespace pt
