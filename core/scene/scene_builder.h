// What the loaders write into: plain, mutable parts of a scene. A Scene is made from a finished
// builder (Scene's constructor validates it and builds the light tables) and is immutable after.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/geometry/instance.h"
#include "core/geometry/mesh.h"
#include "core/geometry/sphere.h"
#include "core/image/texture.h"
#include "core/material/material.h"
#include "core/scene/camera.h"
#include "core/scene/environment.h"
#include "core/scene/lights/directional_light.h"
#include "core/scene/lights/point_light.h"
#include "core/scene/lights/spot_light.h"
#include "core/scene/render_settings.h"
#include "core/scene/up_axis.h"

namespace pt {

// What the default studio lighting added (studio.h), so that the default camera frames the model,
// not the ground, and `pt info` can say what lights the scene.
struct StudioInfo {
  BBox model_bounds;           // the geometry's bounds before the ground was added
  size_t first_triangle = 0;   // the ground's triangles are the mesh's last, from here on
  std::string description;
  std::optional<Camera> camera;  // the default camera the studio was arranged for, if the job chose one
  bool sun = true;               // a sky with a sun (--studio sun), else without (--studio sky)
  UpAxis up = UpAxis::kY;
};

struct SceneBuilder {
  std::string source;                // the file the scene came from, for error messages
  std::vector<std::string> inputs;   // every file read: the scene, OBJs, MTLs, textures
  Mesh mesh;                         // world-space triangles
  // Object-space meshes and where they are placed. A loader adds a mesh once (add_mesh) and places
  // it any number of times (add_instance); resolve_instances() then bakes each mesh placed once
  // into `mesh`, in world space, and keeps a mesh placed more often as one mesh and its instances.
  std::vector<Mesh> meshes;
  std::vector<Instance> instances;
  std::vector<Sphere> spheres;
  std::vector<Material> materials;
  // The surface textures: their cache (made on the first, so a scene without textures never loads
  // OpenImageIO) and how it is made, and the bindings materials' texture slots index.
  SurfaceTextures textures;
  TextureCacheOptions texture_options;
  std::vector<PointLight> point_lights;
  std::vector<SpotLight> spot_lights;
  std::vector<DirectionalLight> directional_lights;
  std::optional<Environment> environment;
  std::optional<Camera> camera;      // none: the render job chooses one that frames the geometry
  RenderSettings settings;
  std::vector<std::string> notes;    // warnings for the user, printed once each
  std::vector<std::string> contents;  // what a file held, for `pt info` (glTF: meshes, instances ...)
  // Materials that look as if they were meant to emit (an MTL Ka far above 1 and no Ke); said
  // only if nothing emits and the default lighting is used instead.
  std::vector<std::string> unlit_hints;
  std::optional<StudioInfo> studio;  // set when the default studio lights the scene

  // The grey Lambertian used where the input names no material; created on first use.
  uint32_t default_material() {
    for (size_t i = 0; i < materials.size(); ++i) {
      if (materials[i].name == "default") return static_cast<uint32_t>(i);
    }
    Material m;
    m.name = "default";
    materials.push_back(m);
    return static_cast<uint32_t>(materials.size() - 1);
  }
  uint32_t add_material(const Material& m) {
    materials.push_back(m);
    return static_cast<uint32_t>(materials.size() - 1);
  }

  // Adds an object-space mesh (its material ids index `materials`); returns its id for add_instance.
  uint32_t add_mesh(Mesh m);
  // Places mesh `mesh` in the world by `to_world`. Throws pt::Error naming `source` for an unknown
  // mesh or a transform instance_transform_problem() refuses (a loader checks first to name the value).
  void add_instance(uint32_t mesh, const Transform& to_world);
  // Bakes every mesh placed once into `mesh` (in the order of its placement), drops meshes placed
  // nowhere, and renumbers the rest. read_scene() calls it once all the files are read, before the
  // default lighting; Scene's constructor calls it again (a no-op by then).
  void resolve_instances();

  bool has_geometry() const { return mesh.triangle_count() > 0 || !spheres.empty() || !instances.empty(); }
  // Of all the geometry: the world mesh, every instance and the spheres.
  BBox geometry_bounds() const;
  // Calls f(material id) for every triangle and sphere, instanced meshes once per mesh.
  template <class F> void for_each_used_material(F&& f) const {
    for (uint32_t m : mesh.material) f(m);
    for (const Mesh& object : meshes) {
      for (uint32_t m : object.material) f(m);
    }
    for (const Sphere& s : spheres) f(s.material);
  }
};

}  // namespace pt
