// A render job: the one path from settings to a renderable image. prepare_job() does, in order,
//   load the scene -> apply the settings overrides -> build the acceleration structure ->
//   decide the camera -> make the integrator -> fill the render options,
// and `pt render`, `pt info`, every `pt bench` and the tests' render helpers use it, so a scene is
// seen the same way everywhere. image_metadata() is the one place that names the pt:* keys.
#pragma once
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "core/accel/accel.h"
#include "core/scene/loader.h"
#include "core/scene/scene.h"
#include "core/scene/studio.h"
#include "core/scene/up_axis.h"
#include "integrators/integrator.h"
#include "renderer/render/aov.h"
#include "renderer/farm/part.h"
#include "renderer/render/render.h"

namespace pt {

// How to look at the scene, from the command line. Each part given replaces that part of the scene
// file's camera, or of the default camera; vectors are written "X,Y,Z".
struct ViewOptions {
  std::optional<std::string> look_from, look_at, up;
  std::optional<float> fov;   // vertical, degrees
  std::optional<float> ortho_height;  // --ortho-height: an orthographic camera's film height
  UpAxis up_axis = UpAxis::kY;  // the default camera's (and default lighting's) up
  Studio studio = Studio::kSun;  // the default lighting where nothing emits
  std::optional<int> camera;   // --camera N: a glTF file's camera N
  std::optional<std::string> env;  // --env FILE: an environment map lighting the scene (replaces the file's)
  float env_rotate = 0.0f;     // --env-rotate DEG, about +y
  float env_strength = 1.0f;   // --env-strength S, multiplies the map
  TextureCacheOptions textures;  // --texture-filter, --texture-cache: how surface textures are looked up
  bool any_camera() const { return look_from || look_at || up || fov; }
};

// A scene and the settings that override its own (the command line wins over the scene file).
// Names are parsed where they are read (cli_options.cpp, the scene file): these are values.
struct JobOptions {
  std::string scene_path;
  std::optional<int> spp, shadow_rays, max_depth;
  std::optional<uint64_t> seed;
  std::optional<std::string> resolution;  // "WxH"
  std::optional<IntegratorKind> integrator;
  std::optional<Strategy> strategy;
  std::optional<SamplerKind> sampler;
  std::optional<std::string> part;  // "K/N": render part K of N (renderer/farm/part.h)
  SplitKind split = SplitKind::kRegions;  // how a frame is split into parts
  std::optional<RussianRoulette> rr;
  std::optional<int> splits;  // kSplitsAuto or a count (IntegratorOptions::splits)
  std::optional<int> emitter_edges;  // kEmitterEdgesAuto or a count, 0 = off (RenderOptions::emitter_edges)
  // Chosen when the Scene is made (Scene::sampling_choices): prepare_job(options) loads the scene
  // with them; a scene handed to prepare_job must have been made with the same.
  std::optional<SkySampling> sky_sampling;
  std::optional<MirrorSampling> mirror_sampling;
  std::optional<LightSampling> light_sampling;
  std::optional<LightSelection> light_selection;
  // Adaptive sampling (renderer/render/render.h): on with `adaptive` or a target error; the threshold
  // defaults to the target error, else 0.01. With a target and no spp, the spp is a large cap.
  bool adaptive = false;
  std::optional<double> adaptive_threshold;
  double target_error = 0;
  AccelOptions accel;  // --backend, --triangle-test, --embree-robust
  ViewOptions view;
  std::optional<AovSet> aov;  // --aov: the EXR's AOV channels (aov.h); default: variance
};

struct Job {
  std::string scene_path;              // as given, for messages and metadata
  std::shared_ptr<const Scene> scene;
  RenderSettings settings;             // the scene file's, with the overrides applied
  IntegratorKind integrator_kind = IntegratorKind::kDirect;
  IntegratorOptions integrator_options;
  AccelOptions accel_options;
  std::unique_ptr<Accel> accel;
  bool default_camera = false;         // the camera was chosen to frame the scene (none was given)
  std::string camera_source;           // where the camera came from, for `pt info`
  UpAxis up_axis = UpAxis::kY;
  std::unique_ptr<Integrator> integrator;
  // The scene's sampling choices (Scene::sampling_choices) and the job's own (Russian roulette's
  // placement under --rr auto), one line each, for `pt info` and the render's header.
  std::vector<std::string> sampling_choices;
  RenderOptions render;                // size, spp, seed, sampler and the camera
  AovSet aovs;                         // the channels an EXR of this render carries
};

// A scene file's settings with the options' overrides applied. Throws pt::Error on a bad --res.
RenderSettings job_settings(const RenderSettings& file, const JobOptions& options);

// The choices a scene is made with under settings `s` (Scene::sampling_choices): s.choices, and the
// sky light-sampled where direct lighting samples only lights.
SceneChoices scene_choices(const RenderSettings& s);

// What the loader needs from the options (--studio, --up-axis).
LoadOptions load_options(const JobOptions& options);

// Loads options.scene_path as a render job sees it. Where nothing emits, the default studio
// lighting is arranged for the camera (its sun to the camera's left), so the default camera is
// chosen here when neither the scene file nor the command line names one: on the scene's own
// acceleration structure (options.accel), which is handed out through `accel` (when given) for
// prepare_job to render with, so that it is built once.
std::shared_ptr<const Scene> load_job_scene(const JobOptions& options, std::unique_ptr<Accel>* accel = nullptr);

// load_job_scene, then prepare_job. Throws pt::Error (naming the file, or the option).
Job prepare_job(const JobOptions& options);
// Prepares a scene already loaded (options.scene_path is used only for messages and metadata).
// `accel`, where given, was built on scene->geometry() with options.accel (load_job_scene's).
Job prepare_job(std::shared_ptr<const Scene> scene, const JobOptions& options, std::unique_ptr<Accel> accel = nullptr);

RenderResult render(const Job& job, const RenderControl& control = {});

// The pt:* metadata of an image rendered by `job`: scene and a hash of every file it read,
// integrator, backend, sampler, seed, camera, samples per pixel (least and most), all settings;
// for a part of a split render also the part keys (renderer/farm/part_file.h).
std::map<std::string, std::string> image_metadata(const Job& job, const RenderResult& result);

// One line of every setting, as `pt info` prints it and the pt:settings metadata holds it.
std::string settings_summary(const RenderSettings& s);

// The camera as command-line flags that reproduce it exactly (shortest round-trip numbers):
// "--look-from X,Y,Z --look-at X,Y,Z --up X,Y,Z --fov DEG".
std::string camera_flags(const Camera& camera);

}  // namespace pt
