// The `pt bench` subcommands, one file each: rays (backend speed and agreement), converge (error
// against time), stability (where intersection methods fail).
#pragma once
#include "renderer/commands/commands.h"

namespace pt {

void add_bench_rays(CLI::App& bench, Action& action);
void add_bench_converge(CLI::App& bench, Action& action);
void add_bench_stability(CLI::App& bench, Action& action);
void add_bench_lights(CLI::App& bench, Action& action);

}  // namespace pt
