// The `pt` subcommands. Each registers itself on the CLI11 app and sets `action` when chosen;
// main runs the action and maps errors to exit codes (2 for bad input or usage, 1 otherwise).
#pragma once
#include <CLI/CLI.hpp>

#include <functional>

namespace pt {

using Action = std::function<int()>;

void add_render_command(CLI::App& app, Action& action);
void add_info_command(CLI::App& app, Action& action);
void add_bench_command(CLI::App& app, Action& action);
void add_gen_command(CLI::App& app, Action& action);
void add_merge_command(CLI::App& app, Action& action);

// Prints the scene's loader notes (warnings) once each, as "pt: warning: ..." lines on stderr.
class Scene;
void print_notes(const Scene& scene);

}  // namespace pt
