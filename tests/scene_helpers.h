// Small scenes built in code for the tests, and rendering them through the one job path
// (renderer/render/job.h), as `pt render` does.
#pragma once
#include <memory>
#include <optional>
#include <string>

#include "core/scene/scene.h"
#include "core/scene/scene_builder.h"
#include "integrators/integrator.h"
#include "renderer/render/job.h"

namespace pt::test {

// Adds the two triangles of the quad a, b, c, d (in order around it) with material m; the front
// face is the side cross(b - a, c - a) points to.
inline void add_quad(SceneBuilder& scene, Vec3f a, Vec3f b, Vec3f c, Vec3f d, uint32_t m) {
  Mesh& mesh = scene.mesh;
  uint32_t base = static_cast<uint32_t>(mesh.positions.size());
  mesh.positions.insert(mesh.positions.end(), {a, b, c, d});
  mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  mesh.material.insert(mesh.material.end(), {m, m});
}

// An axis-aligned box of 12 triangles sharing 24 corners (4 per face, so each face is a closed quad
// and the box is closed); faces point outward, or inward when `inward`.
inline void add_box(SceneBuilder& scene, Vec3f lo, Vec3f hi, uint32_t m, bool inward) {
  for (int k = 0; k < 3; ++k) {
    int u = (k + 1) % 3, v = (k + 2) % 3;  // e_u x e_v = e_k
    for (int side = 0; side < 2; ++side) {
      auto corner = [&](float cu, float cv) {
        Vec3f p;
        p[k] = side ? hi[k] : lo[k];
        p[u] = cu;
        p[v] = cv;
        return p;
      };
      Vec3f a = corner(lo[u], lo[v]), b = corner(hi[u], lo[v]), c = corner(hi[u], hi[v]), d = corner(lo[u], hi[v]);
      bool plus_k = (side == 1) != inward;  // the face's normal is +e_k
      if (plus_k) {
        add_quad(scene, a, b, c, d, m);
      } else {
        add_quad(scene, a, d, c, b, m);
      }
    }
  }
}

// Adds m under a name of its own (its index) and returns its index.
inline uint32_t add_material(SceneBuilder& scene, Material m) {
  m.name = std::to_string(scene.materials.size());
  return scene.add_material(m);
}

inline Material diffuse(Spectrum kd, Spectrum emission = Spectrum(0.0f)) {
  Material m;
  m.model = Diffuse{kd};
  m.emission = emission;
  return m;
}

inline void add_sphere(SceneBuilder& scene, Vec3f center, float radius, uint32_t m) {
  Sphere s;
  s.center = center;
  s.radius = radius;
  s.material = m;
  scene.spheres.push_back(s);
}

inline void set_view(SceneBuilder& scene, Vec3f position, Vec3f look_at, float vfov, int width, int height) {
  Camera cam;
  cam.position = position;
  cam.look_at = look_at;
  cam.vfov_degrees = vfov;
  scene.camera = cam;
  scene.settings.width = width;
  scene.settings.height = height;
}

inline std::shared_ptr<const Scene> finish(SceneBuilder&& scene) {
  return std::make_shared<const Scene>(std::move(scene));
}

// A job for `scene` with the settings `options` overrides; `integrator`, when given, replaces the
// integrator's options in full (tests vary what the command line does not offer, e.g. rr_depth).
inline Job make_job(const std::shared_ptr<const Scene>& scene, const JobOptions& options,
                    const std::optional<IntegratorOptions>& integrator = {}) {
  Job job = prepare_job(scene, options);
  if (integrator) {
    job.integrator_options = *integrator;
    job.integrator = make_integrator(job.integrator_kind, *integrator);
  }
  return job;
}

}  // namespace pt::test
