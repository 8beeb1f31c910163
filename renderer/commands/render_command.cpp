// `pt render SCENE`: load, build the chosen backend, render in passes, write EXR or PNG.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>

#include "core/image/image.h"
#include "core/image/tonemap.h"
#include "core/util/error.h"
#include "core/util/file_extension.h"
#include "core/util/output_file.h"
#include "renderer/commands/cli_options.h"
#include "renderer/commands/commands.h"
#include "renderer/render/interrupt.h"
#include "renderer/render/job.h"
#include "renderer/render/output_format.h"
#include "renderer/farm/part_file.h"
#include "renderer/render/progress.h"

namespace pt {
namespace fs = std::filesystem;
namespace {

struct RenderArgs {
  JobOptions job;
  std::string output;
  int threads = 0;
  double time_budget = 0;
  std::optional<float> exposure;
  Tonemap tonemap = Tonemap::kClip;
  bool quiet = false;
  std::string resume;  // a part file to continue (--resume)
  bool check = false;  // prepare the job and stop: the scene and every option are valid
  bool timing = false;  // one line of phase timings at the end (renderer/bench/split_cost.py reads it)
};

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// A name for the output when none is given, in the current folder: the scene's folder name for a
// folder or a scene.json, else the file's stem. "./scene.json", "." and "dir/" name their folder.
std::string default_output(const std::string& scene_path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::path(scene_path), ec);
  if (ec) p = fs::absolute(fs::path(scene_path)).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  std::string name;
  if (fs::is_directory(p, ec)) {
    name = p.filename().string();
  } else if (p.filename() == "scene.json") {
    name = p.parent_path().filename().string();
  } else {
    name = p.stem().string();
  }
  if (name.empty() || name == "." || name == "..") name = "render";
  return name + ".png";
}

// Before any work: a format we write, and a path we may replace (output_file.h).
void check_output(const std::string& path) {
  output_format(path);  // a documented extension, or a one-line error listing them
  check_output_path(path);
}

// An output that is one of the files the scene was read from would be overwritten by its own render.
void check_not_an_input(const std::string& output, const Scene& scene) {
  std::error_code ec;
  for (const std::string& input : scene.inputs()) {
    if (fs::equivalent(output, input, ec)) {
      throw Error(output, "is one of the scene's own inputs (" + input + "); choose another output");
    }
  }
}

// --resume: the part file to continue, read and checked before any work. Without --part the
// render takes the file's part; with it, they must agree.
std::optional<PartFile> read_resume(RenderArgs& args) {
  if (args.resume.empty()) return std::nullopt;
  PartFile part = read_part(args.resume);
  std::string split = kSplitNames.name(part.part.split);
  if (!args.job.part) {
    args.job.part = part.part.name();
    args.job.split = part.part.split;
  } else if (Part asked = parse_part(*args.job.part, args.job.split);
             asked.index != part.part.index || asked.count != part.part.count || asked.split != part.part.split) {
    throw Error(args.resume, "is part " + part.part.name() + " split by " + split + ", not --part " + *args.job.part +
                                 " --split " + kSplitNames.name(args.job.split));
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
    if (lower_extension(output) != ".exr") throw Error(output, "a part is written as EXR, which carries its exact sums: use -o NAME.exr");
  }
  check_output(output);
  const OutputFormat format = output_format(output);
  if (args.job.aov && format != OutputFormat::kExr && !args.job.part) {
    throw Error(output, "--aov adds channels to an EXR image; use -o NAME.exr");
  }
  auto t_prepare = std::chrono::steady_clock::now();
  Job job = prepare_job(args.job);
  double prepare_seconds = seconds_since(t_prepare);
  check_not_an_input(output, *job.scene);
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
  if (!is_display_referred(format) && !job.render.part && (args.exposure || args.tonemap != Tonemap::kClip)) {
    const char* what = !args.exposure ? "--tonemap has" : args.tonemap != Tonemap::kClip ? "--exposure and --tonemap have" : "--exposure has";
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
                 args.job.scene_path.c_str(), job.scene->geometry().world_triangle_count(), job.scene->spheres().size(), s.width,
                 s.height, job.render.spp, kIntegratorNames.name(s.integrator), kSamplerNames.name(s.sampler), job.accel->name().c_str(),
                 job.accel->stats().build_seconds);
    for (const std::string& choice : job.sampling_choices) std::fprintf(stderr, "pt: %s\n", choice.c_str());
  }
  keep_work_on_interrupt(true);  // from here a signal stops the render and the image is written
  RenderResult result = render(job, control);
  progress.finish();

  auto t_write = std::chrono::steady_clock::now();
  std::map<std::string, std::string> metadata = image_metadata(job, result);
  // Samples per pixel held, least and most (over the part's pixels for a part).
  uint32_t lo = static_cast<uint32_t>(std::stoul(metadata["pt:spp"])), hi = static_cast<uint32_t>(std::stoul(metadata["pt:spp_max"]));
  if (result.film.max_count() == 0 && !resume) {
    if (result.interrupted) {
      std::fprintf(stderr, "pt: interrupted (%s) before any sample was taken; no image written\n", interrupt_signal_name());
      return interrupted_exit_code();
    }
    throw Error(args.job.scene_path, "every sample (" + std::to_string(result.nonfinite) +
                                         ") was NaN or infinite; no image written (are emitters or lights near the float limit?)");
  }
  size_t clamped = 0;
  if (job.render.part) {
    write_part(output, result.film, *job.render.part, metadata);
  } else {
    Image image = format == OutputFormat::kExr ? result.film.to_image(job.aovs, &clamped) : result.film.to_image(false, &clamped);
    image.metadata = std::move(metadata);
    if (result.estimated_error >= 0) image.metadata["pt:estimated_error"] = std::to_string(result.estimated_error);
    if (is_display_referred(format)) apply_tonemap(image, args.tonemap, args.exposure.value_or(0.0f));
    write_image(output, image);
  }
  if (args.timing) {
    // Load, build and the rest of the preparation; rendering; hashing the inputs and writing.
    double build = job.accel->stats().build_seconds;
    std::fprintf(stderr, "pt: timing: load %.4f build %.4f render %.4f write %.4f seconds\n", prepare_seconds - build, build,
                 result.seconds, seconds_since(t_write));
  }

  if (clamped > 0) {
    std::fprintf(stderr, "pt: warning: %zu pixel values (mean or variance) exceeded the float range and were clamped to 3.4e38\n",
                 clamped);
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
                  "(8-bit sRGB after --exposure and --tonemap); default: <scene name>.png")
      ->check([](const std::string& s) { return s.empty() ? std::string("an empty file name") : std::string(); });
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores); the image does not depend on it")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--time", args->time_budget, "Stop after the pass that crosses this many seconds")
      ->check(finite_number(0.0, 1e12, true));
  cmd->add_option("--exposure", args->exposure, "Exposure in stops for 8-bit outputs (.png, .jpg)")->check(finite_number(-40.0, 40.0));
  add_name_option(*cmd, "--tonemap", args->tonemap, kTonemapNames,
                  "Tone curve for 8-bit outputs: clip (default), aces (Narkowicz's ACES fit) or filmic (Hable's); "
                  "core/image/tonemap.h");
  cmd->add_option_function<std::string>(
         "--aov", [&job = args->job](const std::string& list) { job.aov = AovSet::parse(list); },
         "EXR channels beside R G B, comma-separated: variance (the default), albedo, normal, depth, samples, "
         "nonfinite; all; none (README: Output)")
      ->check(CLI::Validator(
          [](std::string& list) -> std::string {
            try {
              AovSet::parse(list);
              return "";
            } catch (const Error& e) {
              std::string message = e.what();  // "--aov 'x': ...": CLI11 names the option itself
              size_t cut = message.rfind("--aov ", 0) == 0 ? message.find(": ") : std::string::npos;
              return cut == std::string::npos ? message : message.substr(cut + 2);
            }
          },
          "LIST"));
  cmd->add_flag("--adaptive", args->job.adaptive,
                "Adaptive sampling: each pixel gets samples in proportion to its neighbours' deviation (the noisiest tenth "
                "every pass, --spp is the cap), and none once its neighbours' estimated relative error is below the threshold");
  cmd->add_option("--adaptive-threshold", args->job.adaptive_threshold,
                  "Per-pixel relative error at which adaptive sampling pauses a pixel (default 0.01, or half the --target-error)")
      ->check(finite_number(1e-6, 10.0));
  cmd->add_option("--target-error", args->job.target_error,
                  "Stop when the image's estimated relative error (root mean square over the pixels, each pixel's from the "
                  "difference between the mean of its samples and of its even-numbered half) is at most this, e.g. 0.02; "
                  "turns on --adaptive; --spp becomes a cap (default 65536)")
      ->check(finite_number(1e-6, 10.0));
  cmd->add_flag("-q,--quiet", args->quiet, "No progress or summary on stderr");
  cmd->add_option("--resume", args->resume,
                  "Continue this part file (an interrupted or time-limited --part render) from its next sample; "
                  "the result equals an uninterrupted render");
  cmd->add_flag("--check", args->check, "Load the scene and check every option, then stop without rendering");
  cmd->add_flag("--timing", args->timing, "Print the seconds spent loading, building, rendering and writing");
  cmd->callback([&action, args] { action = [args] { return run_render(*args); }; });
}

void print_notes(const Scene& scene) {
  for (const std::string& note : scene.notes()) std::fprintf(stderr, "pt: warning: %s\n", printable(note).c_str());
}

}  // namespace pt
