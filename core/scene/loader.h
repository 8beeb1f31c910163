// Scene loading: a bare OBJ (with its MTL) or a JSON scene file that places OBJs, spheres and lights.
#pragma once
#include <string>

#include "core/math/transform.h"
#include "core/scene/scene.h"
#include "core/scene/scene_builder.h"
#include "core/scene/studio.h"
#include "core/scene/up_axis.h"

namespace pt {

// How to complete a scene that does not light itself (the command line's --studio, --up-axis).
struct LoadOptions {
  Studio studio = Studio::kSun;
  UpAxis up_axis = UpAxis::kY;
  bool default_lighting = true;  // false: the caller adds it (the render job, which knows the camera)
  int camera = -1;               // --camera N: a glTF file's camera N instead of its first
  std::string environment;       // --env: an environment map that replaces the scene's
  float environment_rotation = 0.0f, environment_strength = 1.0f;
  TextureCacheOptions textures = {};  // the surface textures' cache (--texture-cache, --texture-filter)
};

// Reads `path` by its extension (.obj or .json; a folder means its scene.json) into a builder and
// adds the default lighting where nothing emits. Throws pt::Error naming the file.
SceneBuilder read_scene(const std::string& path, const LoadOptions& options = {});
// read_scene, then the finished scene.
inline Scene load_scene(const std::string& path, const LoadOptions& options = {}) {
  return Scene(read_scene(path, options));
}

// Appends an OBJ's triangles (transformed to world space) and materials (obj_loader.cpp). When
// `override_material` is >= 0 every face uses it instead of the MTL's materials. The triangles go
// to `into` when given (an object-space mesh for SceneBuilder::add_mesh), else to scene.mesh.
void load_obj(SceneBuilder& scene, const std::string& path, const Transform& transform, int override_material = -1,
              Mesh* into = nullptr);

// Appends a PLY mesh's triangles (ply_loader.cpp), with its vertex colours as a white diffuse
// material's colour unless `override_material` is >= 0; to `into` when given, as load_obj.
void load_ply(SceneBuilder& scene, const std::string& path, const Transform& transform, int override_material = -1,
              Mesh* into = nullptr);

// What to take from a glTF file besides its geometry and lights: its camera (the first one the
// scene places, or `camera` when >= 0; --camera N) when `take_camera`.
struct GltfOptions {
  bool take_camera = false;
  int camera = -1;
};

// Appends a glTF 2.0 scene (.gltf or .glb; gltf_loader.cpp): its meshes placed by its nodes, then
// by `transform`, its materials (or `override_material` when >= 0), point lights and camera.
void load_gltf(SceneBuilder& scene, const std::string& path, const Transform& transform, int override_material = -1,
               const GltfOptions& options = {});

// The largest JSON scene file read (documented in scenes/README.md).
constexpr uint64_t kMaxSceneFileBytes = uint64_t(64) << 20;

// Parses a JSON scene file into `scene` (scene_file.cpp).
void load_scene_file(SceneBuilder& scene, const std::string& path);

// Whether anything in the scene emits light: a point light, the environment, an emissive surface.
bool emits_light(const SceneBuilder& scene);

// If nothing in the scene emits light, adds the default lighting (studio.h: ground and sky, the sun
// to the left of `view`; or with Studio::kNone a white environment of radiance 1) and says so in
// the notes.
void add_default_lighting(SceneBuilder& scene, const LoadOptions& options = {}, std::optional<Vec3f> view = {});

// Registers a surface texture once however many materials use it (making the scene's texture cache,
// and so loading OpenImageIO, on the first) and returns the index of a binding of it placed as
// `placement` says (its `texture` field is ignored): what a material's texture slot holds. A colour
// texture stored as integers is sRGB-decoded, data (normals, roughness) is read as stored.
int texture_index(SceneBuilder& scene, const std::string& path, const std::string& referenced_from,
                  TextureEncoding encoding = TextureEncoding::kColour, const TextureBinding& placement = {});
// The same for an image held in memory (inside a glTF file), named `name`; `mime` ("image/png",
// "image/jpeg" or empty) or else the bytes' signature say its kind.
int texture_index_bytes(SceneBuilder& scene, const std::string& name, const std::vector<unsigned char>& bytes,
                        const std::string& mime, TextureEncoding encoding = TextureEncoding::kColour,
                        const TextureBinding& placement = {});
// Reads an environment map whole (lat-long, bilinear: core/scene/environment.h) and lists it in the
// scene's inputs.
std::shared_ptr<const Texture> environment_image(SceneBuilder& scene, const std::string& path,
                                                 const std::string& referenced_from);

}  // namespace pt
