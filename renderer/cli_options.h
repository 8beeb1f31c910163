// The command-line options shared by `pt render`, `pt info` and the benches: the scene, its
// settings overrides and the backend, registered on a CLI11 subcommand into a JobOptions.
#pragma once
#include <CLI/CLI.hpp>

#include "renderer/job.h"

namespace pt {

// with_render_settings = false registers only the scene and the backend options.
void add_job_options(CLI::App& cmd, JobOptions& o, bool with_render_settings = true);

}  // namespace pt
