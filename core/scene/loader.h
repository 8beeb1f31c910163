// Scene loading: a bare OBJ (with its MTL) or a JSON scene file that places OBJs, spheres and lights.
#pragma once
#include <functional>
#include <string>

#include "core/math/transform.h"
#include "core/scene/scene.h"

namespace pt {

// Loads `path` by its extension (.obj or .json) and finalizes the scene. Throws pt::Error.
// `override_settings`, when given, adjusts the scene's render settings (the command line wins over
// the file) before the scene is finalized, so the default camera fits the final resolution.
Scene load_scene(const std::string& path, const std::function<void(RenderSettings&)>& override_settings = {});

// Appends an OBJ's triangles (transformed to world space) and materials to `scene`. When
// `override_material` is >= 0 every face uses it instead of the MTL's materials.
void load_obj(Scene& scene, const std::string& path, const Transform& transform, int override_material = -1);

// Parses a JSON scene file into `scene` (not finalized).
void load_scene_file(Scene& scene, const std::string& path);

// Adds the default white environment if nothing in the scene emits light, and says so in the notes.
void add_default_lighting(Scene& scene);

// Caches textures by path so a map used by many materials is read once.
int texture_index(Scene& scene, const std::string& path, const std::string& referenced_from);

}  // namespace pt
