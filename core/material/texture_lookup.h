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

  // The texel value of texture `index` at uv times `factor`; `factor` alone when index < 0.
  Spectrum scale(int index, const Spectrum& factor) const {
    return index >= 0 ? (*textures)[index]->lookup(uv) * factor : factor;
  }
};

}  // namespace pt
