#include "renderer/render/job.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>

#include "core/scene/loader.h"
#include "core/util/error.h"
#include "renderer/render/default_camera.h"
#include "renderer/farm/part_file.h"

namespace pt {
namespace {

// The sample cap of a render that stops at a target error and was given no --spp.
constexpr int kTargetErrorMaxSpp = 65536;

void apply_overrides(const JobOptions& o, RenderSettings& s) {
  if (o.spp) s.spp = *o.spp;
  if (o.shadow_rays) s.shadow_rays = *o.shadow_rays;
  if (o.max_depth) s.max_depth = *o.max_depth;
  if (o.seed) s.seed = *o.seed;
  if (o.integrator) s.integrator = *o.integrator;
  if (o.strategy) s.strategy = *o.strategy;
  if (o.sampler) s.sampler = *o.sampler;
  if (o.rr) s.rr = *o.rr;
  if (o.splits) s.splits = *o.splits;
  if (o.emitter_edges) s.emitter_edges = *o.emitter_edges;
  if (o.sky_sampling) s.choices.sky_sampling = *o.sky_sampling;
  if (o.mirror_sampling) s.choices.mirror_sampling = *o.mirror_sampling;
  if (o.light_sampling) s.choices.light_sampling = *o.light_sampling;
  if (o.light_selection) s.choices.light_selection = *o.light_selection;
  if (o.resolution) {
    std::smatch m;
    if (!std::regex_match(*o.resolution, m, std::regex(R"((\d{1,9})x(\d{1,9}))"))) {
      throw Error("--res " + quote(*o.resolution) + ": expected WIDTHxHEIGHT, e.g. 640x480");
    }
    long w = std::stol(m[1]), h = std::stol(m[2]);
    if (!RenderSettings::valid_resolution(w, h)) {
      throw Error("--res " + quote(*o.resolution) + ": each side must be 1 to " + std::to_string(RenderSettings::kMaxSide) +
                  " and the image at most " + std::to_string(RenderSettings::kMaxPixels >> 20) + " Mpixels");
    }
    s.width = static_cast<int>(w);
    s.height = static_cast<int>(h);
  }
}

// "X,Y,Z": three finite numbers, as --look-from, --look-at and --up take them.
Vec3f parse_vec3(const std::string& text, const char* option) {
  Vec3f v;
  const char* p = text.c_str();
  for (int i = 0; i < 3; ++i) {
    char* end = nullptr;
    double d = std::strtod(p, &end);
    bool separator_ok = i < 2 ? *end == ',' : *end == '\0';
    if (end == p || !separator_ok || !std::isfinite(d) || std::abs(d) > 1e30) {
      throw Error(std::string(option) + " '" + text + "': expected three numbers X,Y,Z, e.g. 0,1,5");
    }
    v[i] = static_cast<float>(d);
    p = end + 1;
  }
  return v;
}

// The render camera, decided once: the scene file's, or a position given on the command line, or
// the default camera that frames the model; then each part the command line gives replaces the
// camera's own.
// The view options, checked and parsed.
struct ParsedView {
  std::optional<Vec3f> from, at, up;
  std::optional<float> fov;
  UpAxis axis = UpAxis::kY;
};

ParsedView parse_view(const ViewOptions& v) {
  ParsedView p;
  if (v.look_from) p.from = parse_vec3(*v.look_from, "--look-from");
  if (v.look_at) p.at = parse_vec3(*v.look_at, "--look-at");
  if (v.up) p.up = parse_vec3(*v.up, "--up");
  if (v.fov && !(*v.fov > 0.0f && *v.fov < 180.0f)) throw Error("--fov: expected degrees in (0, 180)");
  if (p.up && !(length(*p.up) > 0)) throw Error("--up '" + *v.up + "': the zero vector has no direction");
  p.fov = v.fov;
  p.axis = v.up_axis;
  return p;
}

Camera decide_camera(const Scene& scene, const Accel& accel, const ViewOptions& v, float aspect, Job& job) {
  auto [from, at, up, fov, axis] = parse_view(v);
  std::string flags;
  for (auto [given, name] : {std::pair{v.look_from.has_value(), "--look-from"}, {v.look_at.has_value(), "--look-at"},
                             {v.up.has_value(), "--up"}, {v.fov.has_value(), "--fov"},
                             {v.ortho_height.has_value(), "--ortho-height"}}) {
    if (given) flags += (flags.empty() ? "" : " ") + std::string(name);
  }
  std::string with = flags.empty() ? "" : ", with " + flags + " from the command line";
  Camera c;
  if (scene.camera()) {
    c = *scene.camera();
    job.camera_source = "the scene file's" + with;
  } else if (from) {
    c.look_at = scene.bounds().center();
    c.up = up_vector(job.up_axis);
    job.camera_source = "from the command line (" + flags + ")" + (at ? "" : ", looking at the centre of the bounds");
  } else {
    // The studio was arranged for the default camera (load_job_scene chose it, on the model
    // alone, with these same options); otherwise choose it now.
    bool arranged = scene.studio() && scene.studio()->camera;
    c = arranged ? *scene.studio()->camera
                 : choose_default_camera(scene, accel, aspect, job.up_axis, fov.value_or(c.vfov_degrees));
    job.default_camera = true;
    job.camera_source = "default: frames the bounds from the side that sees most of the model (the front on ties)" + with;
  }
  if (from) c.position = *from;
  if (at) c.look_at = *at;
  if (up) c.up = *up;
  if (v.fov && v.ortho_height) throw Error("--fov and --ortho-height: a camera is perspective or orthographic, not both");
  if (v.fov) c.vfov_degrees = *v.fov, c.ortho_height = 0.0f;
  if (v.ortho_height) c.ortho_height = *v.ortho_height;
  Vec3f f = c.look_at - c.position;
  if (!(length(f) > 0)) throw Error("--look-from and --look-at: the camera would look from the point it looks at");
  if (!(length(cross(f, c.up)) > 1e-6f * length(f) * length(c.up))) {
    throw Error(std::string(v.up ? "--up" : "--look-from/--look-at") +
                ": the view direction is parallel to the up vector; give another --up");
  }
  // Embree asserts on rays from farther out (kMaxCameraCoordinate); the scene's own camera was
  // checked with the scene, so only the command line can put it there.
  if (!within_extent(c.position, kMaxCameraCoordinate) || !within_extent(c.look_at, kMaxCameraCoordinate)) {
    throw Error("--look-from/--look-at: the camera lies beyond +-1e17, where rays cannot be traced");
  }
  return c;
}

// The shortest text that reads back as the same float.
std::string shortest(float v) {
  char buf[32];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, end) : std::to_string(v);
}

// FNV-1a over the bytes of every file the scene was read from, so the parts of a split render can
// be checked to come from the same inputs.
std::string inputs_hash(const Scene& scene) {
  uint64_t h = 0xcbf29ce484222325ULL;
  char buf[65536];
  for (const std::string& path : scene.inputs()) {
    std::ifstream in(path, std::ios::binary);
    while (in.read(buf, sizeof buf) || in.gcount() > 0) {
      for (std::streamsize i = 0; i < in.gcount(); ++i) h = (h ^ static_cast<unsigned char>(buf[i])) * 0x100000001b3ULL;
    }
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

}  // namespace

RenderSettings job_settings(const RenderSettings& file, const JobOptions& options) {
  RenderSettings s = file;
  apply_overrides(options, s);
  return s;
}

SceneChoices scene_choices(const RenderSettings& s) {
  SceneChoices c = s.choices;
  // Direct lighting by light sampling alone finds the sky only if the sky is a light.
  if (c.sky_sampling == SkySampling::kAuto && s.integrator == IntegratorKind::kDirect && s.strategy == Strategy::kLight) {
    c.sky_sampling = SkySampling::kLight;
  }
  return c;
}

LoadOptions load_options(const JobOptions& options) {
  LoadOptions l;
  l.studio = options.view.studio;
  l.up_axis = options.view.up_axis;
  l.camera = options.view.camera.value_or(-1);
  l.textures = options.view.textures;
  if (options.view.env) {
    l.environment = *options.view.env;
    l.environment_rotation = options.view.env_rotate;
    l.environment_strength = options.view.env_strength;
  } else if (options.view.env_rotate != 0.0f || options.view.env_strength != 1.0f) {
    throw Error("--env-rotate and --env-strength apply to the map given with --env");
  }
  return l;
}

std::shared_ptr<const Scene> load_job_scene(const JobOptions& o, std::unique_ptr<Accel>* accel_out) {
  LoadOptions l = load_options(o);
  ParsedView v = parse_view(o.view);
  l.default_lighting = false;
  SceneBuilder b = read_scene(o.scene_path, l);
  b.settings = job_settings(b.settings, o);  // the settings the scene is made with
  b.settings.choices = scene_choices(b.settings);
  bool studio = l.studio != Studio::kNone && b.has_geometry() && !emits_light(b);
  // The studio's sun stands to the left of the camera. A camera the scene file or the command line
  // places is known now; the default camera is chosen below by tracing the scene itself.
  bool placed = v.from.has_value() || b.camera.has_value();
  // The model is checked before the studio's ground, sized on it, is laid: a model beyond what
  // can be traced is then named as such, not by the ground's overflow.
  if (studio) check_geometry(b, b.source);
  std::optional<Vec3f> view;
  if (studio && placed) {
    BBox bounds = b.geometry_bounds();
    Vec3f at = v.at.value_or(b.camera ? b.camera->look_at : bounds.center());
    view = v.from.value_or(b.camera ? b.camera->position : Vec3f(0.0f)) - at;
  }
  l.default_lighting = true;
  add_default_lighting(b, l, view);
  auto scene = std::make_unique<Scene>(std::move(b));
  if (studio && !placed) {
    // The default camera is chosen on the acceleration structure that will render (built once,
    // with the job's backend), ignoring the studio's ground; the sky is then turned to it. Embree
    // and the BVH agree on the model's hits, so both choose the same camera.
    std::unique_ptr<Accel> accel = make_accel(scene->geometry(), o.accel);
    Camera chosen = choose_default_camera(*scene, *accel, static_cast<float>(scene->settings().width) / scene->settings().height,
                                          v.axis, v.fov.value_or(Camera{}.vfov_degrees));
    scene->arrange_studio(chosen);
    if (accel_out) *accel_out = std::move(accel);
  }
  return scene;
}

Job prepare_job(const JobOptions& options) {
  std::unique_ptr<Accel> accel;
  std::shared_ptr<const Scene> scene = load_job_scene(options, &accel);
  return prepare_job(std::move(scene), options, std::move(accel));
}

Job prepare_job(std::shared_ptr<const Scene> scene, const JobOptions& o, std::unique_ptr<Accel> accel) {
  Job job;
  job.scene_path = o.scene_path.empty() ? scene->source() : o.scene_path;
  job.scene = std::move(scene);
  const Scene& sc = *job.scene;
  job.settings = job_settings(sc.settings(), o);
  if ((o.sky_sampling || o.mirror_sampling || o.light_sampling || o.light_selection) &&
      !(scene_choices(job.settings) == sc.settings().choices)) {
    throw Error(
        "--sky-sampling/--mirror-sampling/--light-sampling/--light-selection: the scene was loaded with other choices (load it "
        "with them)");
  }
  job.settings.choices = sc.settings().choices;
  const RenderSettings& s = job.settings;
  job.integrator_kind = s.integrator;
  job.integrator_options.shadow_rays = s.shadow_rays;
  job.integrator_options.max_depth = s.max_depth;
  job.integrator_options.rr = s.rr;
  job.sampling_choices = sc.sampling_choices();
  if (o.max_depth && job.integrator_kind == IntegratorKind::kDirect) {
    job.sampling_choices.push_back("depth: --max-depth " + std::to_string(*o.max_depth) +
                                   " is not used: this render is direct lighting (light that reaches each visible point "
                                   "straight from an emitter or the sky); --integrator path traces paths that deep");
  }
  if (job.integrator_options.rr == RussianRoulette::kAuto) {
    job.integrator_options.rr = sc.bounce_only_light() ? RussianRoulette::kNextHit : RussianRoulette::kBeforeBounce;
    if (job.integrator_kind == IntegratorKind::kPath) {
      job.sampling_choices.push_back(
          sc.bounce_only_light()
              ? "roulette: at the next hit (some light is found only by bounce rays: a sky left to BSDF sampling, "
                "mirrors or glass; --rr before-bounce overrides)"
              : "roulette: before the bounce ray is traced (every light a bounce ray can hit is light-sampled too; "
                "--rr next-hit overrides)");
    }
  }
  job.integrator_options.splits = s.splits != kSplitsAuto ? s.splits : sc.sky_lit() ? kAutoSplits : 1;
  if (job.integrator_kind == IntegratorKind::kPath && s.splits == kSplitsAuto) {
    job.sampling_choices.push_back(
        sc.sky_lit() ? "splitting: " + std::to_string(kAutoSplits) +
                           " continuations of each camera sample from its first hit (lit by a sky and no emitting "
                           "surface: paths are short and their variance is in the light they gather; --splits 1 "
                           "turns it off)"
                     : std::string("splitting: off (not lit by a sky alone: paths are long, and a continuation costs "
                                   "more than the camera ray it shares; --splits N turns it on)"));
  }
  // Only direct lighting and path tracing count what the camera sees emitted.
  const bool emission_seen = job.integrator_kind == IntegratorKind::kDirect || job.integrator_kind == IntegratorKind::kPath;
  if (!emission_seen) {
    job.render.emitter_edges = 0;
  } else if (s.emitter_edges != kEmitterEdgesAuto) {
    job.render.emitter_edges = s.emitter_edges;
  } else {
    job.render.emitter_edges = sc.surface_lights() ? kAutoEmitterEdges : 0;
    job.sampling_choices.push_back(
        sc.surface_lights()
            ? "emitter edges: " + std::to_string(kAutoEmitterEdges) +
                  " extra camera rays per sample, to the first hit only, in the pixels at the edge of an emitter seen "
                  "directly (found by a ray through each pixel's centre, and around each emitter under two pixels wide; "
                  "--emitter-edges off turns it off)"
            : std::string("emitter edges: off (no surface emits)"));
  }
  job.integrator_options.strategy = s.strategy;
  if (job.integrator_kind == IntegratorKind::kDirect && job.integrator_options.strategy == Strategy::kLight &&
      sc.environment() && !sc.environment_sampled() && luminance(sc.environment()->average()) > 0) {
    throw Error(job.scene_path, "direct lighting with --strategy light needs the sky light-sampled (--sky-sampling light)");
  }
  job.accel_options = o.accel;
  job.up_axis = o.view.up_axis;
  if (o.aov) job.aovs = *o.aov;

  job.accel = accel ? std::move(accel) : make_accel(sc.geometry(), job.accel_options);
  float aspect = static_cast<float>(s.width) / s.height;
  Camera camera = decide_camera(sc, *job.accel, o.view, aspect, job);
  job.integrator = make_integrator(job.integrator_kind, job.integrator_options);
  job.render.width = s.width;
  job.render.height = s.height;
  job.render.spp = s.spp;
  job.render.seed = s.seed;
  job.render.sampler = s.sampler;
  job.render.camera = camera;
  job.render.first_hit = job.aovs.first_hit();
  if (o.part) {
    Part part = parse_part(*o.part, o.split);
    check_part(part, s.width, s.height, s.spp);
    job.render.part = part;
    // A part file has fixed channels (part_file.h): the film's radiance sums and its sample and
    // non-finite counts, not the first-hit AOVs' sums, so nothing would carry --aov to the merge.
    if (o.aov) {
      throw Error("--aov with --part: a part file carries the radiance sums and the samples and nonfinite counts "
                  "only, not AOVs; render AOVs without --part");
    }
  }
  // --target-error turns adaptive sampling on with half the target as each pixel's threshold. A
  // pixel stops on its neighbours' error, and pixels whose own error exceeds their neighbours'
  // (edges) hold the image's mean above the target after their neighbourhoods have stopped; with
  // the target itself as the threshold those few pixels run on alone for many passes (on the
  // hexagonal room at 0.05, 7x the passes and 3.8x the time of half the target). The sample count
  // is then a cap, and without --spp a large one.
  job.render.target_error = o.target_error;
  job.render.adaptive = o.adaptive || o.target_error > 0;
  job.render.adaptive_threshold = o.adaptive_threshold.value_or(o.target_error > 0 ? o.target_error / 2 : 0.01);
  if (o.target_error > 0 && !o.spp) job.render.spp = kTargetErrorMaxSpp;
  if (job.render.adaptive && job.render.part) {
    throw Error("--adaptive/--target-error decide from the whole frame's film: not with --part");
  }
  return job;
}

RenderResult render(const Job& job, const RenderControl& control) {
  return render(*job.scene, *job.accel, *job.integrator, job.render, control);
}

std::map<std::string, std::string> image_metadata(const Job& job, const RenderResult& result) {
  const RenderSettings& s = job.settings;
  std::map<std::string, std::string> m;
  m["pt:scene"] = job.scene_path;
  m["pt:scene_hash"] = inputs_hash(*job.scene);
  m["pt:integrator"] = kIntegratorNames.name(job.integrator_kind);
  m["pt:backend"] = job.accel->name();
  m["pt:sampler"] = kSamplerNames.name(job.render.sampler);
  m["pt:seed"] = std::to_string(job.render.seed);
  m["pt:spp"] = std::to_string(result.film.min_count());
  m["pt:spp_max"] = std::to_string(result.film.max_count());  // above pt:spp only when a pass was cut short
  m["pt:settings"] = settings_summary(s);
  m["pt:camera"] = camera_flags(job.render.camera);
  if (const std::optional<Part>& part = job.render.part) {
    // What a merge or a resume needs to know about a part (renderer/farm/part_file.h).
    const PartRegion region(part, job.render.width, job.render.height);
    uint32_t lo = UINT32_MAX, hi = 0;
    for (int y = 0; y < result.film.height(); ++y) {
      for (int x = 0; x < result.film.width(); ++x) {
        if (!region.contains(x, y)) continue;
        lo = std::min(lo, result.film.count(x, y));
        hi = std::max(hi, result.film.count(x, y));
      }
    }
    m["pt:spp"] = std::to_string(lo == UINT32_MAX ? 0 : lo);
    m["pt:spp_max"] = std::to_string(hi);
    m["pt:part_format"] = kPartFormat;
    m["pt:part"] = part->name();
    m["pt:split"] = kSplitNames.name(part->split);
    m["pt:samples"] = part_samples(part, job.render.spp).name();
    m["pt:frame_spp"] = std::to_string(job.render.spp);
    m["pt:region"] = region.describe();
    m["pt:frame"] = std::to_string(job.render.width) + "x" + std::to_string(job.render.height);
    m["pt:layout"] = PartLayout(part, job.render.width, job.render.height).name();
  }
  return m;
}

std::string camera_flags(const Camera& c) {
  auto vec = [](const Vec3f& v) { return shortest(v.x) + "," + shortest(v.y) + "," + shortest(v.z); };
  return "--look-from " + vec(c.position) + " --look-at " + vec(c.look_at) + " --up " + vec(c.up) +
         (c.orthographic() ? " --ortho-height " + shortest(c.ortho_height) : " --fov " + shortest(c.vfov_degrees));
}

std::string settings_summary(const RenderSettings& s) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%dx%d spp=%d integrator=%s strategy=%s shadow_rays=%d max_depth=%d sampler=%s seed=%llu rr=%s "
                "sky_sampling=%s mirror_sampling=%s light_sampling=%s splits=%s",
                s.width, s.height, s.spp, kIntegratorNames.name(s.integrator), kStrategyNames.name(s.strategy),
                s.shadow_rays, s.max_depth, kSamplerNames.name(s.sampler), static_cast<unsigned long long>(s.seed),
                kRussianRouletteNames.name(s.rr), kSkySamplingNames.name(s.choices.sky_sampling),
                kMirrorSamplingNames.name(s.choices.mirror_sampling), kLightSamplingNames.name(s.choices.light_sampling),
                splits_name(s.splits).c_str());
  // Only when forced, so that the summary (and pt:settings) of every render that leaves it to the
  // scene is what it was before there was a choice.
  std::string summary = buf;
  if (s.choices.light_selection != LightSelection::kAuto) {
    summary += std::string(" light_selection=") + kLightSelectionNames.name(s.choices.light_selection);
  }
  if (s.emitter_edges != kEmitterEdgesAuto) summary += " emitter_edges=" + emitter_edges_name(s.emitter_edges);
  return summary;
}

}  // namespace pt
