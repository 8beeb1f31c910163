// The command-line options shared by `pt render`, `pt info` and the benches: the scene, its
// settings overrides and the backend, registered on a CLI11 subcommand into a JobOptions.
#pragma once
#include <CLI/CLI.hpp>

#include "renderer/job.h"

namespace pt {

// with_render_settings = false registers only the scene, the backend and the view options.
void add_job_options(CLI::App& cmd, JobOptions& o, bool with_render_settings = true);

// The camera flags (--look-from, --look-at, --up, --fov) and --up-axis, for commands that take a
// scene without add_job_options (the benches).
void add_view_options(CLI::App& cmd, ViewOptions& v);

}  // namespace pt
