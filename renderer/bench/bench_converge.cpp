// `pt bench converge SCENE --reference REF.exr|analytic`: error against time. For every
// configuration (backend x integrator x strategy x shadow rays x sampler; each option takes a comma
// list) renders at a doubling series of sample counts and writes wall time, RMSE, relative MSE and
// the film's own variance estimate to CSV. A reference path that does not exist yet is rendered
// once (long, Embree, a seed apart from the measured renders so their noise is independent) and
// reused; its settings travel in the EXR's metadata and are checked on reuse.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>

#include "core/image/image.h"
#include "core/scene/loader.h"
#include "core/util/error.h"
#include "renderer/measure/analytic.h"
#include "renderer/bench/bench.h"
#include "renderer/bench/bench_csv.h"
#include "renderer/measure/converge.h"
#include "renderer/commands/cli_options.h"
#include "renderer/render/progress.h"
#include "renderer/render/interrupt.h"
#include "renderer/render/job.h"

namespace pt {
namespace fs = std::filesystem;
namespace {

struct ConvergeArgs {
  std::string scene, reference, csv;
  std::string backends = "embree", triangle_tests = "watertight", integrators, strategies, shadow_rays, samplers;
  std::optional<std::string> resolution;
  std::optional<int> max_depth;
  bool embree_robust = false;
  int min_spp = 1, max_spp = 256, reference_spp = 4096, threads = 0;
  uint64_t seed = 0;
  bool quiet = false;
  ViewOptions view;
  std::string rr = "auto", sky_sampling = "auto", mirror_sampling = "auto", light_sampling = "auto", light_selection = "auto", adaptive = "off",
              splits = "auto", emitter_edges = "auto";
  double adaptive_threshold = 0.01;
};

// The reference seed differs from the measured renders' so the two noises are independent (with
// the same seed the first samples would coincide and the error would look smaller than it is).
constexpr uint64_t kReferenceSeedOffset = 1000003;

std::string reference_key(const std::string& scene, IntegratorKind integrator, int max_depth, int w, int h,
                          const ViewOptions& view) {
  std::string key = fs::absolute(scene).lexically_normal().string() + "|" + kIntegratorNames.name(integrator) + "|max_depth=" +
                    std::to_string(max_depth) + "|" + std::to_string(w) + "x" + std::to_string(h);
  // A view given on the command line is part of what the reference shows (none: keys stay as before).
  if (view.any_camera() || view.up_axis != UpAxis::kY || view.studio != Studio::kSun) {
    key += "|view=" + view.look_from.value_or("") + ";" + view.look_at.value_or("") + ";" + view.up.value_or("") + ";" +
           (view.fov ? std::to_string(*view.fov) : "") + ";" + kUpAxisNames.name(view.up_axis) + ";" +
           kStudioNames.name(view.studio);
  }
  return key;
}

// The reference: long, Embree (the fastest backend we have; its own noise is reported), Sobol,
// one MIS light sample per vertex, a seed apart from the measured renders'.
Job reference_job(const std::shared_ptr<const Scene>& scene, const JobOptions& base, const ConvergeArgs& a,
                  IntegratorKind integrator) {
  JobOptions o = base;
  o.integrator = integrator;
  o.spp = a.reference_spp;
  o.seed = a.seed + kReferenceSeedOffset;
  o.sampler = SamplerKind::kSobol;
  o.strategy = Strategy::kMis;
  o.shadow_rays = 1;
  o.accel = AccelOptions{};
  return prepare_job(scene, o);
}

Image make_reference(const Job& job, const ConvergeArgs& a) {
  RenderControl control;
  control.threads = a.threads;
  control.cancel = &g_interrupted;
  Progress progress(a.quiet);
  control.on_pass = [&](int done, int total, double seconds, uint64_t rays) { progress.update(done, total, seconds, rays, 0); };
  if (!a.quiet) {
    std::fprintf(stderr,
                 "pt: %s does not exist: rendering it first (%d spp, %s), a long render (minutes to tens of "
                 "minutes; the progress line shows the time left); later runs reuse it\n",
                 a.reference.c_str(), a.reference_spp, kIntegratorNames.name(job.settings.integrator));
  }
  // A fresh clone has no build/refs/: make the reference's folder.
  if (fs::path dir = fs::path(a.reference).parent_path(); !dir.empty()) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw Error(a.reference, "cannot create its folder: " + ec.message());
  }
  RenderResult result = render(job, control);
  progress.finish();
  if (result.interrupted) throw Error(a.reference, "interrupted; no reference written");
  Image image = result.film.to_image(true);
  image.metadata = image_metadata(job, result);
  const RenderSettings& s = job.settings;
  image.metadata["pt:reference"] = reference_key(a.scene, s.integrator, s.max_depth, s.width, s.height, a.view);
  image.metadata["pt:seconds"] = std::to_string(result.seconds);
  write_image(a.reference, image);
  if (!a.quiet) std::fprintf(stderr, "pt: wrote the reference %s in %s\n", a.reference.c_str(), format_seconds(result.seconds).c_str());
  return image;
}

Image load_reference(const std::shared_ptr<const Scene>& scene, const JobOptions& base, const ConvergeArgs& a,
                     IntegratorKind integrator) {
  const RenderSettings s = job_settings(scene->settings(), base);
  const int max_depth = s.max_depth;
  if (!fs::exists(a.reference)) return make_reference(reference_job(scene, base, a, integrator), a);
  Image image = read_image(a.reference);
  if (image.width != s.width || image.height != s.height) {
    throw Error(a.reference, "is " + std::to_string(image.width) + "x" + std::to_string(image.height) + " but the renders are " +
                                 std::to_string(s.width) + "x" + std::to_string(s.height) + " (delete it to remake it, or pass --res)");
  }
  auto key = image.metadata.find("pt:reference");
  if (key != image.metadata.end()) {
    std::string want = reference_key(a.scene, integrator, max_depth, s.width, s.height, a.view);
    if (key->second != want) {
      throw Error(a.reference, "was made for '" + key->second + "', not '" + want + "' (delete it to remake it)");
    }
  } else {
    auto it = image.metadata.find("pt:integrator");
    if (it != image.metadata.end() && it->second != kIntegratorNames.name(integrator)) {
      throw Error(a.reference, "was rendered with the " + it->second + " integrator, not " + kIntegratorNames.name(integrator));
    }
  }
  if (!a.quiet) {
    auto spp = image.metadata.find("pt:spp");
    std::fprintf(stderr, "pt: reusing the reference %s (%s spp)\n", a.reference.c_str(),
                 spp != image.metadata.end() ? spp->second.c_str() : "unknown");
  }
  return image;
}

// Each comma list of names parsed into values through its table; an empty option takes `fallback`.
template <class E, size_t N>
std::vector<E> values(const NameTable<E, N>& table, const std::string& given, const char* option, E fallback) {
  std::vector<E> out;
  if (given.empty()) return {fallback};
  for (const std::string& name : split_list(given)) {
    if (!table.contains(name)) throw Error(std::string(option) + " " + quote(name) + ": expected " + table.list());
    out.push_back(table.parse(name));
  }
  if (out.empty()) throw Error(std::string(option) + ": an empty list");
  return out;
}

std::vector<int> counts(const std::string& given, const char* option, int fallback, int lo, int hi, bool allow_auto) {
  if (given.empty()) return {fallback};
  std::vector<int> out;
  for (const std::string& text : split_list(given)) {
    if (allow_auto && text == "auto") {
      out.push_back(kSplitsAuto);
      continue;
    }
    int n = 0;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
    if (ec != std::errc() || end != text.data() + text.size() || n < lo || n > hi) {
      throw Error(std::string(option) + " " + quote(text) + ": expected " + (allow_auto ? "auto or " : "") + "whole numbers " +
                  std::to_string(lo) + " to " + std::to_string(hi));
    }
    out.push_back(n);
  }
  if (out.empty()) throw Error(std::string(option) + ": an empty list");
  return out;
}

std::vector<int> emitter_edge_counts(const std::string& given) {
  std::vector<int> out;
  for (const std::string& text : split_list(given.empty() ? "auto" : given)) {
    std::optional<int> n = parse_emitter_edges(text);
    if (!n) {
      throw Error("--emitter-edges " + quote(text) + ": expected auto, off or whole numbers 0 to " +
                  std::to_string(kMaxEmitterEdges));
    }
    out.push_back(*n);
  }
  if (out.empty()) throw Error("--emitter-edges: an empty list");
  return out;
}

std::vector<ConvergeConfig> make_configs(const ConvergeArgs& a, const RenderSettings& s) {
  std::vector<bool> adaptive;
  for (const std::string& v : split_list(a.adaptive.empty() ? "off" : a.adaptive)) {
    if (v != "on" && v != "off") throw Error("--adaptive '" + v + "': on or off");
    adaptive.push_back(v == "on");
  }
  std::vector<ConvergeConfig> configs;
  for (Backend backend : values(kBackendNames, a.backends, "--backend", Backend::kEmbree)) {
    std::vector<TriangleTest> tests = backend == Backend::kBvh
                                          ? values(kTriangleTestNames, a.triangle_tests, "--triangle-test", TriangleTest::kWatertight)
                                          : std::vector<TriangleTest>{TriangleTest::kMollerTrumbore};
    for (TriangleTest test : tests) {
      for (IntegratorKind integrator : values(kIntegratorNames, a.integrators, "--integrator", s.integrator)) {
        if (integrator != IntegratorKind::kDirect && integrator != IntegratorKind::kPath) {
          throw Error(std::string("--integrator '") + kIntegratorNames.name(integrator) + "': direct or path");
        }
        // Path tracing always takes one MIS light sample per vertex: strategy and shadow rays do
        // not apply, so it is measured once.
        bool path = integrator == IntegratorKind::kPath;
        std::vector<Strategy> strategies =
            path ? std::vector<Strategy>{Strategy::kMis} : values(kStrategyNames, a.strategies, "--strategy", s.strategy);
        std::vector<int> rays = path ? std::vector<int>{1} : counts(a.shadow_rays, "--shadow-rays", s.shadow_rays, 1, 1024, false);
        for (Strategy strategy : strategies) {
          for (int n : rays) {
            for (SamplerKind sampler : values(kSamplerNames, a.samplers, "--sampler", s.sampler)) {
              for (RussianRoulette rr : values(kRussianRouletteNames, a.rr, "--rr", RussianRoulette::kAuto)) {
              for (SkySampling sky : values(kSkySamplingNames, a.sky_sampling, "--sky-sampling", SkySampling::kAuto)) {
              for (MirrorSampling mirrors : values(kMirrorSamplingNames, a.mirror_sampling, "--mirror-sampling", MirrorSampling::kAuto)) {
              for (LightSampling lights : values(kLightSamplingNames, a.light_sampling, "--light-sampling", LightSampling::kAuto)) {
              for (LightSelection selection : values(kLightSelectionNames, a.light_selection, "--light-selection", LightSelection::kAuto)) {
              for (int splits : counts(a.splits, "--splits", kSplitsAuto, 1, kMaxSplits, true)) {
              for (int edges : emitter_edge_counts(a.emitter_edges)) {
              for (bool adapt : adaptive) {
              ConvergeConfig c;
              c.accel.backend = backend;
              c.accel.triangle_test = test;
              c.accel.embree_robust = a.embree_robust;
              c.integrator = integrator;
              c.strategy = strategy;
              c.shadow_rays = n;
              c.sampler = sampler;
              c.rr = rr;
              c.choices = {sky, mirrors, lights, selection};
              c.splits = splits;
              c.adaptive = adapt;
              c.adaptive_threshold = a.adaptive_threshold;
              c.emitter_edges = edges;
              configs.push_back(c);
              }
              }
              }
              }
              }
              }
              }
              }
            }
          }
        }
      }
    }
  }
  return configs;
}

int run_converge(const ConvergeArgs& a) {
  if (a.min_spp < 1 || a.max_spp < a.min_spp) throw Error("--min-spp and --max-spp: 1 <= min <= max");
  JobOptions base;
  base.scene_path = a.scene;
  base.resolution = a.resolution;
  base.max_depth = a.max_depth;
  base.seed = a.seed;
  base.view = a.view;
  auto scene = load_job_scene(base);
  print_notes(*scene);
  const RenderSettings s = job_settings(scene->settings(), base);
  std::vector<ConvergeConfig> configs = make_configs(a, s);

  // One reference per integrator: direct lighting and path tracing converge to different images.
  std::map<IntegratorKind, Image> references;
  std::map<IntegratorKind, std::string> cases;
  for (const ConvergeConfig& c : configs) {
    if (references.count(c.integrator)) continue;
    if (a.reference == "analytic") {
      cases[c.integrator] = analytic_case(*scene, c.integrator, s.max_depth);
      references[c.integrator] = analytic_reference(prepare_job(scene, c.job_options(base)));
    } else {
      if (!references.empty()) throw Error("--reference " + a.reference + " holds one integrator's image; measure one integrator per run");
      cases[c.integrator] = "reference";
      references[c.integrator] = load_reference(scene, base, a, c.integrator);
    }
  }
  std::string csv_path = a.csv.empty() ? fs::path(a.scene).stem().string() + "-converge.csv" : a.csv;
  if (fs::is_directory(a.scene)) csv_path = a.csv.empty() ? fs::path(a.scene).filename().string() + "-converge.csv" : a.csv;
  check_output_path(csv_path);  // before the measurements, not after

  ConvergeOptions o;
  o.min_spp = a.min_spp;
  o.max_spp = a.max_spp;
  o.threads = a.threads;

  std::ostringstream csv;
  csv << "scene,case,config,backend,triangle_test,embree_robust,integrator,strategy,shadow_rays,sampler,width,height,"
         "max_depth,spp,seconds,build_seconds,rays,mse,rmse,rel_mse,film_var,ref_var,efficiency,rr,sky_sampling,"
         "mirror_sampling,adaptive,est_rel_err,min_pixel_spp,max_pixel_spp,splits,block_chi2,light_sampling,light_selection,emitter_edges\n";
  std::printf("%-40s %7s %9s %11s %11s %11s %11s\n", "configuration", "spp", "seconds", "rmse", "rel_mse", "sqrt(var)",
              "1/(mse*t)");
  std::vector<ConvergeRow> all;
  for (const ConvergeConfig& config : configs) {
    const Image& ref = references[config.integrator];
    double ref_var = mean_variance(ref);
    std::vector<ConvergeRow> rows = run_convergence(scene, base, {config}, ref, o, [&](const ConvergeRow& r) {
      double eff = r.error.mse > 0 && r.seconds > 0 ? 1.0 / (r.error.mse * r.seconds) : 0.0;
      std::printf("%-40s %7d %9.4f %11.4e %11.4e %11.4e %11.4e\n", config.label().c_str(), r.spp, r.seconds, r.error.rmse,
                  r.error.rel_mse, std::sqrt(r.error.film_var), eff);
      std::fflush(stdout);
      char line[1024];
      std::snprintf(line, sizeof line,
                    "%s,%s,%s,%s,%s,%d,%s,%s,%d,%s,%d,%d,%d,%d,%.6f,%.6f,%llu,%.9e,%.9e,%.9e,%.9e,%.9e,%.9e,%s,%s,%s,%s,%.6e,%u,%u,%s,%.4f,%s,%s,%s\n",
                    a.scene.c_str(), cases[config.integrator].c_str(), config.label().c_str(),
                    kBackendNames.name(config.accel.backend),
                    config.accel.backend == Backend::kBvh ? kTriangleTestNames.name(config.accel.triangle_test) : "",
                    config.accel.embree_robust ? 1 : 0, kIntegratorNames.name(config.integrator),
                    kStrategyNames.name(config.strategy), config.shadow_rays, kSamplerNames.name(config.sampler), s.width,
                    s.height, s.max_depth, r.spp, r.seconds, r.build_seconds, static_cast<unsigned long long>(r.rays),
                    r.error.mse, r.error.rmse, r.error.rel_mse, r.error.film_var, ref_var, eff,
                    kRussianRouletteNames.name(config.rr), kSkySamplingNames.name(config.choices.sky_sampling),
                    kMirrorSamplingNames.name(config.choices.mirror_sampling), config.adaptive ? "on" : "off",
                    r.estimated_error, r.min_spp, r.max_spp, splits_name(config.splits).c_str(), r.error.block_chi2,
                    kLightSamplingNames.name(config.choices.light_sampling),
                    kLightSelectionNames.name(config.choices.light_selection),
                    emitter_edges_name(config.emitter_edges).c_str());
      csv << line;
    });
    all.insert(all.end(), rows.begin(), rows.end());
  }
  write_text_file(csv_path, csv.str());

  // The slope of RMSE against spp on log-log axes: -0.5 is plain Monte Carlo; steeper means the
  // sampler's stratification pays (Owen-scrambled Sobol on smooth integrands).
  std::printf("\n%-40s %12s %14s\n", "configuration", "rmse slope", "1/(mse*t) max");
  for (const ConvergeConfig& config : configs) {
    std::vector<double> spp, rmse;
    double eff = 0;
    for (const ConvergeRow& r : all) {
      if (r.config.label() != config.label() || !(r.error.rmse > 0)) continue;
      spp.push_back(r.spp);
      rmse.push_back(r.error.rmse);
      if (r.seconds > 0) eff = 1.0 / (r.error.mse * r.seconds);
    }
    double slope = spp.size() >= 2 ? log_log_slope(spp, rmse) : std::nan("");
    std::printf("%-40s %12.3f %14.4e\n", config.label().c_str(), slope, eff);
  }
  if (!a.quiet) std::fprintf(stderr, "pt: wrote %s\n", csv_path.c_str());
  return 0;
}

}  // namespace

void add_bench_converge(CLI::App& bench, Action& action) {
  auto a = std::make_shared<ConvergeArgs>();
  CLI::App* cmd = bench.add_subcommand("converge", "Error against time: renders at doubling sample counts per configuration, writes CSV");
  cmd->add_option("scene", a->scene, "Scene: .obj, .json or a folder with scene.json")->required();
  cmd->add_option("--reference", a->reference,
                  "'analytic' (closed-form scenes in scenes/analytic) or an EXR; a missing EXR is rendered once and reused")
      ->required();
  cmd->add_option("--reference-spp", a->reference_spp, "Samples per pixel of a reference made here")->check(CLI::Range(1, 1 << 24));
  cmd->add_option("--backend", a->backends, "Comma list: embree,bvh");
  cmd->add_option("--triangle-test", a->triangle_tests, "Comma list for the bvh backend: mt,watertight");
  cmd->add_flag("--embree-robust", a->embree_robust, "Build Embree's scene with RTC_SCENE_FLAG_ROBUST");
  cmd->add_option("--integrator", a->integrators, "Comma list: direct,path (default: the scene's)");
  cmd->add_option("--strategy", a->strategies, "Comma list for direct: light,bsdf,mis (default: the scene's)");
  cmd->add_option("--shadow-rays", a->shadow_rays, "Comma list for direct, e.g. 1,4 (default: the scene's)");
  cmd->add_option("--sampler", a->samplers, "Comma list: sobol,independent (default: the scene's)");
  cmd->add_option("--rr", a->rr, "Comma list for path: auto,next-hit,before-bounce (Russian roulette placement)");
  cmd->add_option("--sky-sampling", a->sky_sampling, "Comma list: auto,light,bsdf");
  cmd->add_option("--mirror-sampling", a->mirror_sampling, "Comma list: auto,on,off");
  cmd->add_option("--light-sampling", a->light_sampling, "Comma list: auto,area,solid-angle (triangle lights)");
  cmd->add_option("--light-selection", a->light_selection, "Comma list: auto,power,tree (which light a sample goes to)");
  cmd->add_option("--splits", a->splits, "Comma list for path: auto or counts, e.g. 1,4,8 (continuations per camera sample)");
  cmd->add_option("--emitter-edges", a->emitter_edges, "Comma list: auto, off or counts, e.g. off,4,8 (extra camera rays in pixels at an emitter's edge)");
  cmd->add_option("--adaptive", a->adaptive, "Comma list: off,on (adaptive sampling; the spp values become caps)");
  cmd->add_option("--adaptive-threshold", a->adaptive_threshold, "Per-pixel relative error threshold of adaptive sampling")
      ->check(finite_number(1e-6, 10.0));
  cmd->add_option("--min-spp", a->min_spp, "Smallest sample count (doubled up to --max-spp)")->check(CLI::Range(1, 1 << 20));
  cmd->add_option("--max-spp", a->max_spp, "Largest sample count")->check(CLI::Range(1, 1 << 20));
  cmd->add_option("--res", a->resolution, "Resolution WIDTHxHEIGHT (default: the scene's)");
  cmd->add_option("--max-depth", a->max_depth, "Maximum bounces (path)")->check(CLI::Range(1, 1024));
  cmd->add_option("--seed", a->seed, "Random seed of the measured renders");
  cmd->add_option("--threads", a->threads, "Worker threads (default: all cores)")->check(CLI::Range(1, 1024));
  cmd->add_option("--csv", a->csv, "CSV output (default: <scene>-converge.csv)");
  cmd->add_flag("-q,--quiet", a->quiet, "No progress on stderr");
  add_view_options(*cmd, a->view);
  cmd->callback([&action, a] { action = [a] { return run_converge(*a); }; });
}

}  // namespace pt
