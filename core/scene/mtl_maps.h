// An MTL material's texture options and its normal and bump maps (norm; bump, map_Bump), for the
// OBJ loader.
#pragma once
#include <tiny_obj_loader.h>

#include <string>

#include "core/scene/obj_validate.h"
#include "core/scene/scene_builder.h"

namespace pt {

// The placement MTL options give a map: -o (offset) and -s (scale) in the OBJ's uv (v up) as a
// UvTransform in texture space (t down), -clamp on as clamped wrapping.
TextureBinding mtl_placement(const tinyobj::texture_option_t& option);

// Sets m.normal_texture (norm, with -bm as its scale) and m.bump_texture (bump / map_Bump, heights
// times -bm in scene units), each read as data. A bump map whose texels hold tangent-space normals
// (looks_like_normal_map: Blender writes its Normal Map node as map_Bump) is read as a normal map
// with -bm as its strength, with a note. A map that is not there is a note naming the MTL
// line, as a missing map_Kd is; the material renders without it.
// True when the texture of `binding` has three channels whose mean is a tangent-space normal
// map's (near (0.5, 0.5, 1), far from grey).
bool looks_like_normal_map(SceneBuilder& scene, int binding);
void add_mtl_normal_maps(SceneBuilder& scene, const tinyobj::material_t& mtl, const MtlFacts* facts,
                         const std::string& dir, const std::string& obj, Material& m);

}  // namespace pt
