#include "core/scene/mtl_maps.h"

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
    m.bump_texture = load(mtl.bump_texname, mtl.bump_texopt, facts ? facts->bump_line : 0, "bump map");
    m.bump_scale = mtl.bump_texopt.bump_multiplier;
  }
}

}  // namespace pt
