// `pt render SCENE`: load, build the chosen backend, render in passes, write EXR or PNG.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>

#include "core/image/image.h"
#include "core/util/error.h"
#include "renderer/cli_options.h"
#include "renderer/commands.h"
#include "renderer/interrupt.h"
#include "renderer/job.h"
#include "renderer/progress.h"

namespace pt {
namespace fs = std::filesystem;
namespace {

struct RenderArgs {
  JobOptions job;
  std::string output;
  int threads = 0;
  double time_budget = 0;
  float exposure = 0;
  bool quiet = false;
};

// A name for the output when none is given: the scene's folder for scene.json, else its stem.
std::string default_output(const std::string& scene_path) {
  fs::path p(scene_path);
  if (fs::is_directory(p)) return p.filename().string() + ".png";
  if (p.filename() == "scene.json" && p.has_parent_path()) return fs::absolute(p).parent_path().filename().string() + ".png";
  return p.stem().string() + ".png";
}

void check_output(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext != ".exr" && ext != ".png" && ext != ".jpg" && ext != ".jpeg" && ext != ".hdr") {
    throw Error(path, "unsupported output format '" + ext + "' (use .exr or .png)");
  }
  fs::path dir = fs::path(path).parent_path();
  if (!dir.empty() && !fs::is_directory(dir)) throw Error(path, "the output folder does not exist");
  if (fs::is_directory(path)) throw Error(path, "is a folder");
  // Find out now, not after an hour of rendering, whether the folder takes new files: create and
  // remove a probe (access(2) would say yes to root even where creation fails, e.g. /proc).
  fs::path probe = (dir.empty() ? fs::path(".") : dir) / (".pt-probe-" + std::to_string(::getpid()));
  int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0) throw Error(path, std::string("cannot write to the output folder: ") + std::strerror(errno));
  ::close(fd);
  ::unlink(probe.c_str());
}

int run_render(const RenderArgs& args) {
  std::string output = args.output.empty() ? default_output(args.job.scene_path) : args.output;
  check_output(output);
  Job job = prepare_job(args.job);
  print_notes(*job.scene);
  const RenderSettings& s = job.settings;
  RenderControl control;
  control.threads = args.threads;
  control.time_budget = args.time_budget;
  control.cancel = &g_interrupted;
  Progress progress(args.quiet);
  control.on_pass = [&](int done, int total, double seconds, uint64_t rays) {
    progress.update(done, total, seconds, rays, args.time_budget);
  };
  if (!args.quiet) {
    std::fprintf(stderr, "pt: rendering %s: %zu triangles, %zu spheres, %dx%d, %d spp, %s, %s, %s (build %.2f s)\n",
                 args.job.scene_path.c_str(), job.scene->mesh().triangle_count(), job.scene->spheres().size(), s.width,
                 s.height, s.spp, s.integrator.c_str(), s.sampler.c_str(), job.accel->name().c_str(),
                 job.accel->stats().build_seconds);
  }
  RenderResult result = render(job, control);
  progress.finish();

  uint32_t lo = result.film.min_count(), hi = result.film.max_count();
  if (hi == 0) {
    std::fprintf(stderr, "pt: interrupted (%s) before any sample was taken; no image written\n", interrupt_signal_name());
    return interrupted_exit_code();
  }
  std::string ext = fs::path(output).extension().string();
  bool exr = ext.size() == 4 && std::tolower(static_cast<unsigned char>(ext[1])) == 'e' &&
             std::tolower(static_cast<unsigned char>(ext[2])) == 'x' && std::tolower(static_cast<unsigned char>(ext[3])) == 'r';
  Image image = result.film.to_image(exr);
  image.metadata = image_metadata(job, result);
  WriteOptions wo;
  wo.exposure = args.exposure;
  write_image(output, image, wo);

  if (result.nonfinite > 0) {
    std::fprintf(stderr, "pt: warning: %llu samples were NaN or infinite and were dropped\n",
                 static_cast<unsigned long long>(result.nonfinite));
  }
  if (result.interrupted) {
    std::fprintf(stderr, "pt: interrupted (%s): wrote %s holding %u%s samples per pixel\n", interrupt_signal_name(),
                 output.c_str(), lo, hi != lo ? (" to " + std::to_string(hi)).c_str() : "");
    return interrupted_exit_code();
  }
  if (!args.quiet) {
    // Say so when the time budget stopped the render before the requested sample count.
    std::string spp = lo < static_cast<uint32_t>(s.spp) ? std::to_string(lo) + " of " + std::to_string(s.spp)
                                                        : std::to_string(lo);
    std::fprintf(stderr, "pt: wrote %s (%s spp, %s, %.1f Mrays/s)\n", output.c_str(), spp.c_str(),
                 format_seconds(result.seconds).c_str(), result.seconds > 0 ? result.rays / result.seconds * 1e-6 : 0.0);
  }
  return 0;
}

}  // namespace

void add_render_command(CLI::App& app, Action& action) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Render a scene (.obj or .json) to an EXR or PNG image");
  add_job_options(*cmd, args->job);
  cmd->add_option("-o,--output", args->output, "Output image: .exr (linear float + variance) or .png (sRGB); default: <scene name>.png");
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores); the image does not depend on it")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--time", args->time_budget, "Stop after the pass that crosses this many seconds")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--exposure", args->exposure, "Exposure in stops for 8-bit outputs")->check(CLI::Range(-40.0, 40.0));
  cmd->add_flag("-q,--quiet", args->quiet, "No progress or summary on stderr");
  cmd->callback([&action, args] { action = [args] { return run_render(*args); }; });
}

void print_notes(const Scene& scene) {
  for (const std::string& note : scene.notes()) std::fprintf(stderr, "pt: warning: %s\n", note.c_str());
}

}  // namespace pt
