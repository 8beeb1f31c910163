// What the scene's materials emit, for the lights made of its surfaces: a radiance per material,
// times, where the material has an emission texture, that texture at the emitting point
// (Material::emission_texture; glTF's emissiveTexture, MTL map_Ke). A textured light is chosen by
// its radiance averaged over its surface (the texture filtered over the light's footprint in uv)
// and gives, where a sample lands, the texture's value there: the choice changes only the variance.
#pragma once
#include <vector>

#include "core/material/texture_lookup.h"
#include "core/math/vec.h"

namespace pt {

struct MaterialEmission {
  std::vector<Spectrum> radiance;      // per material; zero: it does not emit
  std::vector<int> texture;            // per material (or empty): a slot of `textures`, or -1
  const SurfaceTextures* textures = nullptr;

  int texture_of(uint32_t material) const { return material < texture.size() ? texture[material] : -1; }
};

// The sphere's uv at unit normal n, as Scene::interaction maps it.
inline Vec2f sphere_uv(const Vec3f& n) {
  return {0.5f + std::atan2(n.x, n.z) / (2.0f * kPi), 1.0f - std::acos(std::clamp(n.y, -1.0f, 1.0f)) * kInvPi};
}

}  // namespace pt
