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
// Checks for values CLI11's own validators let through: CLI::Range and CLI::PositiveNumber accept
// "nan", and an unsigned option takes "-1" as 2^64-1 and clamps 2^64. A finite number in
// [lo, hi] ((lo, hi] with lo_exclusive); a decimal integer from 0 to 2^64-1.
CLI::Validator finite_number(double lo, double hi, bool lo_exclusive = false);
CLI::Validator unsigned_64();

}  // namespace pt
