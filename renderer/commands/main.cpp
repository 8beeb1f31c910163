// `pt`: render, inspect and benchmark scenes. Errors print one line and exit 2 for bad input or
// usage, 1 for anything else.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "core/util/asan_defaults.h"
#include "core/util/error.h"
#include "renderer/commands/commands.h"
#include "renderer/render/interrupt.h"

namespace {

// "rendr" for "render": CLI11 alone says only that the arguments were not expected.
std::string unknown_command(const CLI::App& app, int argc, char** argv) {
  const CLI::App* at = &app;
  std::string path;
  for (int i = 1; i < argc; ++i) {
    std::string word = argv[i];
    if (word.empty() || word[0] == '-') return "";
    const std::vector<const CLI::App*> subs = at->get_subcommands({});
    auto sub = std::find_if(subs.begin(), subs.end(), [&](const CLI::App* s) { return s->check_name(word); });
    if (sub != subs.end()) {
      at = *sub;
      path += (path.empty() ? "" : " ") + word;
      continue;
    }
    if (subs.empty() || at->get_require_subcommand_min() == 0) return "";
    std::string names;
    for (const CLI::App* s : subs) names += (names.empty() ? "" : ", ") + s->get_name();
    return "unknown command '" + (path.empty() ? word : path + " " + word) + "' (" + (path.empty() ? "pt" : "pt " + path) +
           " has: " + names + ")";
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pt: a path tracer for OBJ and JSON scenes, on Embree or a home-written BVH"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pt 0.1");
  pt::Action action;
  pt::add_render_command(app, action);
  pt::add_info_command(app, action);
  pt::add_bench_command(app, action);
  pt::add_gen_command(app, action);
  pt::add_merge_command(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string unknown = unknown_command(app, argc, argv);
    std::cerr << "pt: error: " << pt::printable(unknown.empty() ? e.what() : unknown) << " (see pt --help)\n";
    return 2;
  }
  pt::install_interrupt_handlers();
  try {
    return action ? action() : 2;
  } catch (const pt::Error& e) {
    std::cerr << "pt: error: " << pt::printable(e.what()) << "\n";
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the input named that the filesystem refuses (a symbolic link loop, a permission):
    // bad input, told as one line naming the path.
    std::string path = e.path1().string();
    std::cerr << "pt: error: " << pt::printable(path.empty() ? "" : path + ": ") << pt::printable(e.code().message()) << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "pt: error: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "pt: error: " << pt::printable(e.what()) << "\n";
    return 1;
  }
}
