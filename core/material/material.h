// A material: a model from core/material/models.h (its parameters and texture slots) and what
// every surface has whatever its model: emission and coverage.
#pragma once
#include <string>

#include "core/material/bsdf.h"
#include "core/material/models.h"

namespace pt {

struct Material {
  std::string name;
  MaterialModel model = Diffuse{};
  Spectrum emission{0.0f};  // radiance leaving the front face; non-zero makes the surface a light
  // Coverage (MTL `d`): the fraction of the surface that is there. Rays pass the rest unchanged:
  // at a hit they go straight on with probability 1 - opacity (stochastic transparency), and a
  // shadow ray lets 1 - opacity through. Lights are opaque (the loaders enforce it).
  float opacity = 1.0f;
  // Surface detail, whatever the model (Scene::shading_normal): a tangent-space normal map (a slot
  // of the scene's texture bindings, read as data; glTF's convention: +X along the tangent, +Y along
  // the bitangent, up in the image, OpenGL style), its xy scaled by normal_scale (glTF's
  // normalTexture.scale, MTL norm -bm); or a height map (first channel) whose heights times
  // bump_scale, in scene units, displace the surface along its normal (MTL bump -bm). -1: none.
  int normal_texture = -1;
  float normal_scale = 1.0f;
  int bump_texture = -1;
  float bump_scale = 1.0f;
  int emission_texture = -1;  // a colour texture slot multiplying `emission` (core/scene/lights/emission.h)

  bool is_emissive() const { return max_component(emission) > 0; }
  // Coverage from a texture's alpha (glTF's base colour alpha under alphaMode MASK or BLEND):
  // opacity times the texture's alpha at the hit, or, with a cutoff > 0 (MASK), 1 where that
  // reaches the cutoff and 0 elsewhere. -1: none.
  int alpha_texture = -1;
  float alpha_cutoff = 0.0f;

  bool is_partly_transparent() const { return opacity < 1.0f || alpha_texture >= 0; }
  bool has_normal_map() const { return normal_texture >= 0 || bump_texture >= 0; }
  // Whether a shading point on it looks up any texture (its model's slots, emission, coverage; a
  // normal or bump map): only then does its footprint need the surface's uv derivatives.
  bool reads_textures() const {
    return has_normal_map() || emission_texture >= 0 || alpha_texture >= 0 ||
           std::visit([](const auto& m) { return m.reads_textures(); }, model);
  }
  const char* type_name() const { return model_name(model); }
  uint8_t flags() const { return model_flags(model); }
  template <class M>
  bool is() const {
    return std::holds_alternative<M>(model);
  }

  std::string describe() const {
    return std::visit([](const auto& m) { return m.describe(); }, model);
  }
  Bsdf bsdf(const TextureLookup& tex) const {
    return std::visit([&](const auto& m) { return Bsdf(m.at(tex)); }, model);
  }
};

}  // namespace pt
