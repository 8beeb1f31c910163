#include "core/scene/mtl_maps.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/scene/loader.h"

namespace pt {
namespace fs = std::filesystem;

TextureBinding mtl_placement(const tinyobj::texture_option_t& option) {
  TextureBinding b;
  // u' = u su + ou, v' = v sv + ov with t = 1 - v: t' = t sv + (1 - sv - ov).
  float su = option.scale[0], sv = option.scale[1];
  b.transform.scale = {su, sv};
  b.transform.offset = {option.origin_offset[0], 1.0f - sv - option.origin_offset[1]};
  if (option.clamp) b.wrap_s = b.wrap_t = TextureWrap::kClamp;
  return b;
}

bool looks_like_normal_map(SceneBuilder& scene, int binding) {
  if (!scene.textures.cache) return false;
  const TextureFileInfo& info = scene.textures.cache->info(scene.textures.bindings[binding].texture);
  if (info.channels < 3 || !info.has_mean) return false;
  const float r = info.mean[0], g = info.mean[1], b = info.mean[2];
  // Unit normals leaning at most ~45 degrees from +z, encoded n * 0.5 + 0.5, average to a blue of
  // at least 0.85 and a red and green near 0.5; a grey height map has blue equal to red.
  return b > 0.75f && std::abs(r - 0.5f) < 0.15f && std::abs(g - 0.5f) < 0.15f && b - std::max(r, g) > 0.2f;
}

void add_mtl_normal_maps(SceneBuilder& scene, const tinyobj::material_t& mtl, const MtlFacts* facts,
                         const std::string& dir, const std::string& obj, Material& m) {
  auto load = [&](const std::string& name, const tinyobj::texture_option_t& option, int line, const char* what) {
    fs::path file = fs::path(dir) / name;
    if (!fs::exists(file)) {
      std::string place = facts ? facts->file + ":" + std::to_string(line) : obj;
      scene.notes.push_back(place + ": " + what + " '" + name + "' not found; material '" + m.name + "' renders without it");
      return -1;
    }
    return texture_index(scene, file.string(), obj, TextureEncoding::kData, mtl_placement(option));
  };
  if (!mtl.normal_texname.empty()) {
    m.normal_texture = load(mtl.normal_texname, mtl.normal_texopt, facts ? facts->norm_line : 0, "normal map");
    m.normal_scale = mtl.normal_texopt.bump_multiplier;
  }
  if (!mtl.bump_texname.empty() && m.normal_texture < 0) {
    int bump = load(mtl.bump_texname, mtl.bump_texopt, facts ? facts->bump_line : 0, "bump map");
    if (bump >= 0 && looks_like_normal_map(scene, bump)) {
      // Blender writes its Normal Map node as map_Bump (-bm its strength) and reads map_Bump back as
      // one. A height map is grey; a tangent-space normal map's mean is
      // near (0.5, 0.5, 1): such a map_Bump is read as a normal map, and said so.
      m.normal_texture = bump;
      m.normal_scale = mtl.bump_texopt.bump_multiplier;
      std::string place = facts ? facts->file + ":" + std::to_string(facts->bump_line) : obj;
      scene.notes.push_back(place + ": bump map '" + mtl.bump_texname + "' of material '" + m.name +
                            "' holds tangent-space normals (its mean colour is bluish, not grey); read as a normal map, as Blender does");
    } else {
      m.bump_texture = bump;
      m.bump_scale = mtl.bump_texopt.bump_multiplier;
    }
  }
}

}  // namespace pt
