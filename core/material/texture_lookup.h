// The one place a material reads its textures at a shading point. Models read every texture slot
// (an index into the scene's texture bindings) through it.
#pragma once
#include <memory>
#include <vector>

#include "core/image/texture_cache.h"
#include "core/material/texture_binding.h"
#include "core/math/vec.h"

namespace pt {

// A scene's surface textures: the bindings its materials' slots index, and the cache that holds
// the texels (null when there are none).
struct SurfaceTextures {
  std::vector<TextureBinding> bindings;
  std::shared_ptr<TextureCache> cache;

  size_t size() const { return bindings.size(); }
  bool empty() const { return bindings.empty(); }
  // Whether lookups filter over a footprint (else rays need no differentials).
  bool filtered() const { return cache && cache->filter() == TextureFilter::kMipmap; }
  // Binding `index`'s query at uv (v up, OBJ's convention) with the footprint duv/dx, duv/dy.
  // `centre`: from uv to the footprint's centre (SurfaceInteraction::duv_centre).
  TextureQuery query(int index, Vec2f uv, Vec2f duvdx, Vec2f duvdy, bool isotropic = false,
                     Vec2f centre = {}) const {
    const TextureBinding& b = bindings[index];
    // Texture space has t down (row 0 at t = 0); pt's uv has v up: t = 1 - v.
    Vec2f st = b.matrix.apply({uv.x, 1.0f - uv.y});
    Vec2f dx = b.matrix.linear({duvdx.x, -duvdx.y});
    Vec2f dy = b.matrix.linear({duvdy.x, -duvdy.y});
    Vec2f dc = b.matrix.linear({centre.x, -centre.y});
    TextureQuery q;
    q.s = st.x, q.t = st.y;
    q.dsdx = dx.x, q.dtdx = dx.y, q.dsdy = dy.x, q.dtdy = dy.y;
    q.dsdc = dc.x, q.dtdc = dc.y;
    q.wrap_s = b.wrap_s, q.wrap_t = b.wrap_t;
    q.isotropic = isotropic;
    return q;
  }
  Spectrum lookup(int index, Vec2f uv, Vec2f duvdx, Vec2f duvdy, bool isotropic = false, Vec2f centre = {}) const {
    return cache->lookup(bindings[index].texture, query(index, uv, duvdx, duvdy, isotropic, centre));
  }
  float lookup_alpha(int index, Vec2f uv, Vec2f duvdx, Vec2f duvdy, bool isotropic = false) const {
    return cache->lookup_alpha(bindings[index].texture, query(index, uv, duvdx, duvdy, isotropic));
  }
};

struct TextureLookup {
  const SurfaceTextures* textures = nullptr;
  Vec2f uv;
  Vec2f duvdx{0.0f, 0.0f}, duvdy{0.0f, 0.0f};  // the ray's footprint (core/scene/footprint.h); zero: a point
  Spectrum color{1.0f};  // the surface's vertex colour (white where the mesh has none)
  bool isotropic = false;  // the footprint of a ray after a rough bounce (RayDifferential::rough)
  Vec2f centre{0.0f, 0.0f};  // from uv to the footprint's centre (SurfaceInteraction::duv_centre)

  // The texel value of texture slot `index` at uv times `factor`; `factor` alone when index < 0.
  Spectrum scale(int index, const Spectrum& factor) const {
    return index >= 0 ? textures->lookup(index, uv, duvdx, duvdy, isotropic, centre) * factor : factor;
  }
  // A base colour: scale() times the vertex colour (glTF COLOR_0 and PLY colours multiply it).
  Spectrum base(int index, const Spectrum& factor) const { return scale(index, factor) * color; }
  // A data texture (roughness, metallic: linear values, not colour), through the same filtered
  // lookup. Its slot's texture was registered as TextureEncoding::kData, so texels are as stored.
  Spectrum data(int index) const { return textures->lookup(index, uv, duvdx, duvdy, isotropic, centre); }
};

}  // namespace pt
