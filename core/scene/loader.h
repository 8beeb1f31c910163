// Scene loading: a bare OBJ (with its MTL) or a JSON scene file that places OBJs, spheres and lights.
#pragma once
#include <string>

#include "core/math/transform.h"
#include "core/scene/scene.h"
#include "core/scene/scene_builder.h"

namespace pt {

// Reads `path` by its extension (.obj or .json; a folder means its scene.json) into a builder and
// adds the default lighting where nothing emits. Throws pt::Error naming the file.
SceneBuilder read_scene(const std::string& path);
// read_scene, then the finished scene.
inline Scene load_scene(const std::string& path) { return Scene(read_scene(path)); }

// Appends an OBJ's triangles (transformed to world space) and materials (obj_loader.cpp). When
// `override_material` is >= 0 every face uses it instead of the MTL's materials.
void load_obj(SceneBuilder& scene, const std::string& path, const Transform& transform, int override_material = -1);

// Parses a JSON scene file into `scene` (scene_file.cpp).
void load_scene_file(SceneBuilder& scene, const std::string& path);

// Adds the default white environment if nothing in the scene emits light, and says so in the notes.
void add_default_lighting(SceneBuilder& scene);

// Reads a texture once however many materials use it; returns its index in scene.textures.
int texture_index(SceneBuilder& scene, const std::string& path, const std::string& referenced_from);

}  // namespace pt
