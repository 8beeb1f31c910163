// The command-line options shared by `pt render`, `pt info` and the benches: the scene, its
// settings overrides and the backend, registered on a CLI11 subcommand into a JobOptions.
#pragma once
#include <CLI/CLI.hpp>

#include "renderer/render/job.h"

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

// An option whose value is one of a name table's names (core/util/names.h), stored as the value it
// names (`target` is the enum or an optional of it): CLI11 checks the name against the table, so
// --help and the error list the names, and the name is parsed once, here.
template <class T, class E, size_t N>
CLI::Option* add_name_option(CLI::App& cmd, const std::string& flag, T& target, const NameTable<E, N>& table,
                             const std::string& help) {
  return cmd.add_option_function<std::string>(flag, [&target, &table](const std::string& name) { target = table.parse(name); },
                                              help)
      ->check(CLI::IsMember(table.names()));
}

// --splits: "auto" (kSplitsAuto) or a count from 1 to kMaxSplits; nullopt for anything else.
std::optional<int> parse_splits(const std::string& text);
// --emitter-edges: "auto" (kEmitterEdgesAuto), "off" (0) or a count up to kMaxEmitterEdges; nullopt otherwise.
std::optional<int> parse_emitter_edges(const std::string& text);

}  // namespace pt
