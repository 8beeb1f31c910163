// `pt render SCENE`: load, build the chosen backend, render in passes, write EXR or PNG.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>

#include "core/image/image.h"
#include "core/image/tonemap.h"
#include "core/util/error.h"
#include "renderer/cli_options.h"
#include "renderer/commands.h"
#include "renderer/interrupt.h"
#include "renderer/job.h"
#include "renderer/output_format.h"
#include "renderer/part_file.h"
#include "renderer/progress.h"

namespace pt {
namespace fs = std::filesystem;
namespace {

struct RenderArgs {
  JobOptions job;
  std::string output;
  int threads = 0;
  double time_budget = 0;
  std::optional<float> exposure;
  std::string tonemap = "clip";
  bool quiet = false;
  std::string resume;  // a part file to continue (--resume)
  bool check = false;  // prepare the job and stop: the scene and every option are valid
  bool timing = false;  // one line of phase timings at the end (renderer/bench_split.py reads it)
};

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// A name for the output when none is given: the scene's folder for scene.json, else its stem.
std::string default_output(const std::string& scene_path) {
  fs::path p(scene_path);
  if (fs::is_directory(p)) return p.filename().string() + ".png";
  if (p.filename() == "scene.json" && p.has_parent_path()) return fs::absolute(p).parent_path().filename().string() + ".png";
  return p.stem().string() + ".png";
}

void check_output(const std::string& path) {
  output_format(path);  // a documented extension, or a one-line error listing them
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

// --resume: the part file to continue, read and checked before any work. Without --part the
// render takes the file's part; with it, they must agree.
std::optional<PartFile> read_resume(RenderArgs& args) {
  if (args.resume.empty()) return std::nullopt;
  PartFile part = read_part(args.resume);
  std::string split = kSplitNames.name(part.part.split);
  if (!args.job.part) {
    args.job.part = part.part.name();
    args.job.split = split;
  } else if (Part asked = parse_part(*args.job.part, kSplitNames.parse(args.job.split));
             asked.index != part.part.index || asked.count != part.part.count || asked.split != part.part.split) {
    throw Error(args.resume, "is part " + part.part.name() + " split by " + split + ", not --part " + *args.job.part +
                                 " --split " + args.job.split);
  }
  return part;
}

// A part's default name: <scene name>.part<K>of<N>.exr.
std::string default_part_output(const std::string& scene_path, const std::string& part) {
  std::string name = fs::path(default_output(scene_path)).stem().string();
  return name + ".part" + part.substr(0, part.find('/')) + "of" + part.substr(part.find('/') + 1) + ".exr";
}

int run_render(RenderArgs args) {
  std::optional<PartFile> resume = read_resume(args);
  std::string output = !args.output.empty() ? args.output
                       : args.job.part     ? default_part_output(args.job.scene_path, *args.job.part)
                                           : default_output(args.job.scene_path);
  if (args.job.part) {
    std::string ext = fs::path(output).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext != ".exr") throw Error(output, "a part is written as EXR, which carries its exact sums: use -o NAME.exr");
  }
  check_output(output);
  const OutputFormat format = output_format(output);
  if (args.job.aov && format != OutputFormat::kExr && !args.job.part) {
    throw Error(output, "--aov adds channels to an EXR image; use -o NAME.exr");
  }
  const Tonemap tonemap = kTonemapNames.parse(args.tonemap);
  auto t_prepare = std::chrono::steady_clock::now();
  Job job = prepare_job(args.job);
  double prepare_seconds = seconds_since(t_prepare);
  print_notes(*job.scene);
  if (resume) {
    RenderResult empty;
    empty.film = resume->film;
    std::string diff = identity_difference(resume->metadata, image_metadata(job, empty));
    if (!diff.empty()) {
      throw Error(args.resume, diff + " in this render (resume a part with the scene and settings it was started with)");
    }
  }
  const RenderSettings& s = job.settings;
  if (args.check) {
    if (!args.quiet) std::fprintf(stderr, "pt: %s and its settings are fine; nothing rendered (--check)\n", args.job.scene_path.c_str());
    return 0;
  }
  if (resume) {
    uint32_t lo = resume->taken_lo, hi = resume->taken_hi;
    std::error_code ec;
    if (lo == static_cast<uint32_t>(resume->samples.size()) && fs::equivalent(args.resume, output, ec)) {
      if (!args.quiet) {
        std::fprintf(stderr, "pt: %s already holds all %d samples of part %s; nothing to do\n", args.resume.c_str(),
                     resume->samples.size(), resume->part.name().c_str());
      }
      return 0;
    }
    if (!args.quiet) {
      std::fprintf(stderr, "pt: resuming part %s from %s, which holds %u%s of its %d samples per pixel\n",
                   resume->part.name().c_str(), args.resume.c_str(), lo, hi != lo ? (" to " + std::to_string(hi)).c_str() : "",
                   resume->samples.size());
    }
  }
  if (!is_display_referred(format) && !job.render.part && (args.exposure || args.tonemap != "clip")) {
    const char* what = !args.exposure ? "--tonemap has" : args.tonemap != "clip" ? "--exposure and --tonemap have" : "--exposure has";
    std::fprintf(stderr, "pt: warning: %s no effect on %s, which holds linear radiance; they apply to .png and .jpg\n", what,
                 output.c_str());
  }
  RenderControl control;
  control.threads = args.threads;
  control.time_budget = args.time_budget;
  control.cancel = &g_interrupted;
  if (resume) control.resume = &resume->film;
  Progress progress(args.quiet);
  if (resume) progress.start_at(static_cast<int>(resume->taken_lo));
  control.on_pass = [&](int done, int total, double seconds, uint64_t rays) {
    progress.update(done, total, seconds, rays, args.time_budget);
  };
  if (!args.quiet) {
    std::fprintf(stderr, "pt: rendering %s: %zu triangles, %zu spheres, %dx%d, %d spp, %s, %s, %s (build %.2f s)\n",
                 args.job.scene_path.c_str(), job.scene->mesh().triangle_count(), job.scene->spheres().size(), s.width,
                 s.height, job.render.spp, s.integrator.c_str(), s.sampler.c_str(), job.accel->name().c_str(),
                 job.accel->stats().build_seconds);
    for (const std::string& choice : job.scene->sampling_choices()) std::fprintf(stderr, "pt: %s\n", choice.c_str());
  }
  RenderResult result = render(job, control);
  progress.finish();

  auto t_write = std::chrono::steady_clock::now();
  std::map<std::string, std::string> metadata = image_metadata(job, result);
  // Samples per pixel held, least and most (over the part's pixels for a part).
  uint32_t lo = static_cast<uint32_t>(std::stoul(metadata["pt:spp"])), hi = static_cast<uint32_t>(std::stoul(metadata["pt:spp_max"]));
  if (result.film.max_count() == 0 && !resume) {
    std::fprintf(stderr, "pt: interrupted (%s) before any sample was taken; no image written\n", interrupt_signal_name());
    return interrupted_exit_code();
  }
  if (job.render.part) {
    write_part(output, result.film, *job.render.part, metadata);
  } else {
    Image image = format == OutputFormat::kExr ? result.film.to_image(job.aovs) : result.film.to_image(false);
    image.metadata = std::move(metadata);
    if (result.estimated_error >= 0) image.metadata["pt:estimated_error"] = std::to_string(result.estimated_error);
    if (is_display_referred(format)) apply_tonemap(image, tonemap, args.exposure.value_or(0.0f));
    write_image(output, image);
  }
  if (args.timing) {
    // Load, build and the rest of the preparation; rendering; hashing the inputs and writing.
    double build = job.accel->stats().build_seconds;
    std::fprintf(stderr, "pt: timing: load %.4f build %.4f render %.4f write %.4f seconds\n", prepare_seconds - build, build,
                 result.seconds, seconds_since(t_write));
  }

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
    uint32_t want = static_cast<uint32_t>(part_samples(job.render.part, s.spp).size());
    std::string spp = job.render.adaptive ? std::to_string(lo) + " to " + std::to_string(hi) + " (adaptive)"
                      : lo < want                ? std::to_string(lo) + " of " + std::to_string(want)
                                                 : std::to_string(lo);
    std::string what = output;
    if (job.render.part) {
      what = "part " + job.render.part->name() + " (" + kSplitNames.name(job.render.part->split) + ", samples " +
             part_samples(job.render.part, s.spp).name() + ") to " + output;
    }
    std::fprintf(stderr, "pt: wrote %s (%s spp, %s, %.1f Mrays/s)\n", what.c_str(), spp.c_str(),
                 format_seconds(result.seconds).c_str(), result.seconds > 0 ? result.rays / result.seconds * 1e-6 : 0.0);
    if (result.estimated_error >= 0) {
      std::fprintf(stderr, "pt: estimated relative error %.4g%s\n", result.estimated_error,
                   args.job.target_error <= 0 ? ""
                   : result.reached_target ? " (target reached)"
                                           : " (target NOT reached: the sample cap or the time budget stopped the render)");
    }
  }
  return 0;
}

}  // namespace

void add_render_command(CLI::App& app, Action& action) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand("render", "Render a scene (.obj or .json) to an EXR or PNG image");
  add_job_options(*cmd, args->job);
  cmd->add_option("-o,--output", args->output,
                  "Output image: .exr (linear float, R G B + the --aov channels), .hdr (linear RGB), .png or .jpg/.jpeg "
                  "(8-bit sRGB after --exposure and --tonemap); default: <scene name>.png");
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores); the image does not depend on it")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--time", args->time_budget, "Stop after the pass that crosses this many seconds")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--exposure", args->exposure, "Exposure in stops for 8-bit outputs (.png, .jpg)")->check(CLI::Range(-40.0, 40.0));
  cmd->add_option("--tonemap", args->tonemap,
                  "Tone curve for 8-bit outputs: clip (default), aces (Narkowicz's ACES fit) or filmic (Hable's); "
                  "core/image/tonemap.h")
      ->check(CLI::IsMember(kTonemapNames.names()));
  cmd->add_option("--aov", args->job.aov,
                  "EXR channels beside R G B, comma-separated: variance (the default), albedo, normal, depth, samples, "
                  "nonfinite; all; none (README: Output)");
  cmd->add_flag("--adaptive", args->job.adaptive,
                "Adaptive sampling: pixels whose neighbours' estimated relative error is below the threshold get no more samples");
  cmd->add_option("--adaptive-threshold", args->job.adaptive_threshold,
                  "Per-pixel relative error at which adaptive sampling pauses a pixel (default 0.01, or the --target-error)")
      ->check(CLI::Range(1e-6, 10.0));
  cmd->add_option("--target-error", args->job.target_error,
                  "Stop when the image's estimated relative error (docs/cycles.md) is at most this; turns on --adaptive; "
                  "--spp becomes a cap (default 65536)")
      ->check(CLI::Range(1e-6, 10.0));
  cmd->add_flag("-q,--quiet", args->quiet, "No progress or summary on stderr");
  cmd->add_option("--resume", args->resume,
                  "Continue this part file (an interrupted or time-limited --part render) from its next sample; "
                  "the result equals an uninterrupted render");
  cmd->add_flag("--check", args->check, "Load the scene and check every option, then stop without rendering");
  cmd->add_flag("--timing", args->timing, "Print the seconds spent loading, building, rendering and writing");
  cmd->callback([&action, args] { action = [args] { return run_render(*args); }; });
}

void print_notes(const Scene& scene) {
  for (const std::string& note : scene.notes()) std::fprintf(stderr, "pt: warning: %s\n", note.c_str());
}

}  // namespace pt
