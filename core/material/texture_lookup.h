// The one place a material reads its textures at a shading point. Models read every texture slot
// through it, so a different texture engine (filtered lookups, ray footprints) changes this file
// only.
#pragma once
#include <memory>
#include <vector>

#include "core/image/texture.h"
#include "core/math/vec.h"

namespace pt {

struct TextureLookup {
  const std::vector<std::shared_ptr<const Texture>>* textures = nullptr;
  Vec2f uv;
  Spectrum color{1.0f};  // the surface's vertex colour (white where the mesh has none)

  // The texel value of texture `index` at uv times `factor`; `factor` alone when index < 0.
  Spectrum scale(int index, const Spectrum& factor) const {
    return index >= 0 ? (*textures)[index]->lookup(uv) * factor : factor;
  }
  // A base colour: scale() times the vertex colour (glTF COLOR_0 and PLY colours multiply it).
  Spectrum base(int index, const Spectrum& factor) const { return scale(index, factor) * color; }
  // A data texture (roughness, metallic: linear values, not colour). The loaders hand data slots a
  // texture read without sRGB decoding (data_texture_index in core/scene/loader.h), so this is the
  // texel value as stored in the file, blended bilinearly.
  Spectrum data(int index) const { return (*textures)[index]->lookup(uv); }
};

}  // namespace pt
