// `pt info SCENE`: what the loader made of a scene, and every default in force.
#include <cstdio>
#include <map>

#include "core/accel/bvh_isa.h"
#include "core/util/error.h"
#include "renderer/commands/cli_options.h"
#include "renderer/commands/commands.h"
#include "renderer/render/job.h"

namespace pt {
namespace {

void print_vec(const char* label, const Vec3f& v) { std::printf("  %-12s (%g, %g, %g)\n", label, v.x, v.y, v.z); }

int run_info(const JobOptions& o) {
  Job job = prepare_job(o);
  const Scene& scene = *job.scene;
  print_notes(scene);
  const Mesh& mesh = scene.mesh();
  std::printf("scene        %s\n", printable(scene.source()).c_str());
  for (const std::string& line : scene.contents()) std::printf("contents     %s\n", printable(line).c_str());
  std::printf("triangles    %zu (%zu degenerate)%s%s\n", mesh.triangle_count(), scene.degenerate_triangles(),
              mesh.corner_normals.empty() ? "" : ", with normals", mesh.corner_uvs.empty() ? "" : ", with uvs");
  std::printf("vertices     %zu\n", mesh.positions.size());
  const Geometry& geometry = scene.geometry();
  if (!geometry.instances().empty()) {
    size_t stored = 0;
    for (const Geometry& o : geometry.objects()) stored += o.mesh().triangle_count();
    std::printf("instances    %zu of %zu meshes (%zu triangles stored, %zu placed)\n", geometry.instances().size(),
                geometry.objects().size(), stored, geometry.world_triangle_count() - mesh.triangle_count());
  }
  std::printf("spheres      %zu\n", scene.spheres().size());
  std::printf("materials    %zu\n", scene.materials().size());
  for (const Material& m : scene.materials()) {
    // Names come from the files (an MTL `newmtl`, a glTF material): escaped like every message.
    std::printf("  %-20s %-10s %s", printable(m.name).c_str(), m.type_name(), m.describe().c_str());
    if (m.is_partly_transparent()) std::printf(" opacity %g", m.opacity);
    if (m.alpha_texture >= 0) std::printf(m.alpha_cutoff > 0 ? " times its texture's alpha, cut at %g" : " times its texture's alpha", m.alpha_cutoff);
    if (m.emission_texture >= 0) std::printf(" emission textured");
    if (m.is_emissive()) std::printf(" emission (%g, %g, %g)", m.emission.x, m.emission.y, m.emission.z);
    std::printf("\n");
  }
  const SurfaceTextures& textures = scene.textures();
  const int files = textures.cache ? textures.cache->count() : 0;
  std::printf("textures     %d\n", files);
  for (int i = 0; i < files; ++i) {
    const TextureFileInfo& t = textures.cache->info(i);
    const std::string held = t.held_first < 0    ? "none held by pt"
                             : t.held_first == 0 ? "all held by pt"
                                                 : "held by pt from " + std::to_string(std::max(1, t.width >> t.held_first)) + "x" +
                                                       std::to_string(std::max(1, t.height >> t.held_first));
    std::printf("  %s: %dx%d, %d channel%s, %s, %s, %s\n", printable(t.path).c_str(), t.width, t.height, t.channels,
                t.channels == 1 ? "" : "s", t.encoding == TextureEncoding::kColour ? "colour (sRGB-decoded if stored as integers)" : "data (as stored)",
                t.mip_levels > 1 ? (std::to_string(t.mip_levels) + " MIP levels in the file").c_str() : "MIP levels made by the cache",
                held.c_str());
  }
  if (files > 0) {
    std::printf("texture lookups  %s, cache bound %g MB (--texture-filter, --texture-cache)\n",
                kTextureFilterNames.name(o.view.textures.filter), static_cast<double>(o.view.textures.max_memory_mb));
  }
  const LightSet& lights = scene.light_set();
  std::printf("lights       %zu: %zu point, %zu spot, %zu emissive triangles, %zu emissive spheres, %zu directional, %zu environment\n",
              lights.lights().size(), lights.count(LightType::kPoint), lights.count(LightType::kSpot),
              lights.count(LightType::kTriangle), lights.count(LightType::kSphere), lights.count(LightType::kDirectional),
              lights.count(LightType::kEnvironment));
  if (scene.environment()) {
    const Environment& env = *scene.environment();
    if (env.has_image()) {
      std::printf("environment  image %s (%dx%d), scale %g, rotation %g degrees\n", printable(env.image()->path).c_str(),
                  env.image()->width, env.image()->height, env.scale(), env.rotation_degrees());
    } else {
      Spectrum c = env.constant();
      std::printf("environment  constant radiance (%g, %g, %g)\n", c.x, c.y, c.z);
    }
  } else {
    std::printf("environment  none (black)\n");
  }
  if (scene.studio()) {
    std::printf("studio       %s (the default lighting: nothing in the scene emits; --studio none switches it off)\n",
                scene.studio()->description.c_str());
  }
  const BBox& b = scene.bounds();
  std::printf("bounds       (%g, %g, %g) to (%g, %g, %g)\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
  const Camera& c = job.render.camera;
  std::printf("camera       %s\n", job.camera_source.c_str());
  print_vec("position", c.position);
  print_vec("look_at", c.look_at);
  print_vec("up", c.up);
  std::printf("  %-12s %g degrees (vertical)\n", "fov", c.vfov_degrees);
  // The same camera as flags to paste after `pt render SCENE` (exact: shortest round-trip numbers).
  std::printf("  %-12s %s%s\n", "as flags", camera_flags(c).c_str(),
              job.up_axis == UpAxis::kY ? "" : (std::string(" --up-axis ") + kUpAxisNames.name(job.up_axis)).c_str());
  const RenderSettings& s = job.settings;
  for (const std::string& choice : job.sampling_choices) std::printf("sampling     %s\n", choice.c_str());
  std::printf("settings     %s\n", settings_summary(s).c_str());
  // The copy of the BVH's kernels this CPU runs (core/accel/bvh_isa.h); Embree picks its own.
  std::string runs;
  for (bvh::Isa isa : bvh::kIsas)
    if (bvh::isa_supported(isa)) runs += std::string(runs.empty() ? "" : ", ") + bvh::isa_name(isa);
  std::printf("bvh kernels  %s (this CPU runs %s; PT_BVH_ISA=NAME picks another of them)\n",
              bvh::isa_name(bvh::active_isa()), runs.c_str());
  return 0;
}

}  // namespace

void add_info_command(CLI::App& app, Action& action) {
  auto o = std::make_shared<JobOptions>();
  CLI::App* cmd = app.add_subcommand("info", "Describe a scene: geometry, materials, lights, bounds and the defaults in force");
  add_job_options(*cmd, *o);
  cmd->callback([&action, o] { action = [o] { return run_info(*o); }; });
}

}  // namespace pt
