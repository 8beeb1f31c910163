// The format dispatcher and what every format shares: default lighting and the texture cache.
#include "core/scene/loader.h"

#include <algorithm>
#include <filesystem>

#include "core/image/image.h"
#include "core/util/error.h"
#include "core/util/file_extension.h"
#include "core/util/input_file.h"

namespace pt {
namespace fs = std::filesystem;

SceneBuilder read_scene(const std::string& path, const LoadOptions& options) {
  FileKind kind = file_kind(path);
  if (kind == FileKind::kMissing) throw Error(path, "no such file");
  if (kind == FileKind::kFolder) {
    fs::path inside = fs::path(path) / "scene.json";
    if (file_kind(inside.string()) != FileKind::kMissing) return read_scene(inside.string(), options);
    throw Error(path, "is a folder without a scene.json");
  }
  require_regular_file(path, "a scene");
  SceneBuilder scene;
  scene.source = path;
  scene.texture_options = options.textures;
  const std::string ext = lower_extension(path);
  if (options.camera >= 0 && ext != ".gltf" && ext != ".glb") {
    throw Error(path, "--camera picks a camera of a glTF file (.gltf, .glb)");
  }
  if (ext == ".obj") {
    load_obj(scene, path, Transform());
  } else if (ext == ".gltf" || ext == ".glb") {
    load_gltf(scene, path, Transform(), -1, GltfOptions{true, options.camera});
  } else if (ext == ".ply") {
    load_ply(scene, path, Transform());
  } else if (ext == ".json") {
    load_scene_file(scene, path);
  } else {
    throw Error(path, "unknown scene format " + quote(ext) + " (expected .obj, .gltf, .glb, .ply or .json)");
  }
  if (!options.environment.empty()) {
    if (scene.environment) scene.notes.push_back(path + ": its environment is replaced by --env " + options.environment);
    scene.environment = Environment(environment_image(scene, options.environment, "--env"), options.environment_strength,
                                    options.environment_rotation);
  }
  scene.resolve_instances();
  if (options.default_lighting) add_default_lighting(scene, options);
  return scene;
}

bool emits_light(const SceneBuilder& scene) {
  bool emits = !scene.point_lights.empty() || !scene.spot_lights.empty() || !scene.directional_lights.empty() ||
               scene.environment.has_value();
  scene.for_each_used_material([&](uint32_t m) { emits = emits || scene.materials[m].is_emissive(); });
  return emits;
}

void add_default_lighting(SceneBuilder& scene, const LoadOptions& options, std::optional<Vec3f> view) {
  if (emits_light(scene)) return;
  if (options.studio == Studio::kNone || !scene.has_geometry()) {
    scene.environment = Environment(Spectrum(1.0f));
    scene.notes.push_back(scene.source + ": nothing in the scene emits light; using the default white environment (radiance 1)");
  } else {
    add_studio(scene, options.studio, options.up_axis, view);
    scene.notes.push_back(scene.source + ": nothing in the scene emits light; lighting it with the default studio: " +
                          scene.studio->description + " (--studio none: a plain white sky)");
  }
  scene.notes.insert(scene.notes.end(), scene.unlit_hints.begin(), scene.unlit_hints.end());
}

namespace {
// The binding of texture `texture` placed as `placement`: an existing one where it is the same.
int binding_index(SceneBuilder& scene, int texture, TextureBinding placement) {
  placement.texture = texture;
  placement.matrix = UvMatrix(placement.transform);
  auto& bindings = scene.textures.bindings;
  for (size_t i = 0; i < bindings.size(); ++i) {
    if (bindings[i] == placement) return static_cast<int>(i);
  }
  bindings.push_back(placement);
  return static_cast<int>(bindings.size() - 1);
}

TextureCache& texture_cache(SceneBuilder& scene) {
  if (!scene.textures.cache) scene.textures.cache = make_texture_cache(scene.texture_options);
  return *scene.textures.cache;
}
}  // namespace

int texture_index(SceneBuilder& scene, const std::string& path, const std::string& referenced_from,
                  TextureEncoding encoding, const TextureBinding& placement) {
  int texture;
  try {
    TextureCache& cache = texture_cache(scene);
    int before = cache.count();
    texture = cache.add(path, encoding);
    if (cache.count() > before && std::find(scene.inputs.begin(), scene.inputs.end(), path) == scene.inputs.end()) {
      scene.inputs.push_back(path);
    }
  } catch (const Error& e) {
    throw Error(referenced_from, std::string("texture will not load: ") + e.what());
  }
  return binding_index(scene, texture, placement);
}

int texture_index_bytes(SceneBuilder& scene, const std::string& name, const std::vector<unsigned char>& bytes,
                        const std::string& mime, TextureEncoding encoding, const TextureBinding& placement) {
  TextureCache& cache = texture_cache(scene);
  for (int i = 0; i < cache.count(); ++i) {
    if (cache.info(i).path == name && cache.info(i).encoding == encoding) return binding_index(scene, i, placement);
  }
  auto starts = [&](std::initializer_list<unsigned char> magic) {
    return bytes.size() >= magic.size() && std::equal(magic.begin(), magic.end(), bytes.begin());
  };
  std::string format = mime == "image/png"    ? "png"
                       : mime == "image/jpeg" ? "jpg"
                       : starts({0x89, 'P', 'N', 'G'}) ? "png"
                       : starts({0xff, 0xd8, 0xff})    ? "jpg"
                                                       : "";
  if (format.empty()) throw Error(name, "an embedded image that is neither PNG nor JPEG" + (mime.empty() ? "" : " (" + quote(mime) + ")"));
  return binding_index(scene, cache.add_memory(name, format, bytes, encoding), placement);
}

std::shared_ptr<const Texture> environment_image(SceneBuilder& scene, const std::string& path,
                                                 const std::string& referenced_from) {
  std::shared_ptr<const Texture> image;
  try {
    image = read_texture(path);
  } catch (const Error& e) {
    throw Error(referenced_from, std::string("texture will not load: ") + e.what());
  }
  scene.inputs.push_back(path);
  return image;
}

}  // namespace pt
