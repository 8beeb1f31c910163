// `pt`: render, inspect and benchmark scenes. Errors print one line and exit 2 for bad input or
// usage, 1 for anything else.
#include <cstdio>
#include <iostream>

#include "core/util/error.h"
#include "renderer/commands.h"
#include "renderer/interrupt.h"

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
    std::cerr << "pt: error: " << e.what() << " (see pt --help)\n";
    return 2;
  }
  pt::install_interrupt_handlers();
  try {
    return action ? action() : 2;
  } catch (const pt::Error& e) {
    std::cerr << "pt: error: " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "pt: error: out of memory\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "pt: error: " << e.what() << "\n";
    return 1;
  }
}
