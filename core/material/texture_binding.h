// A material's texture slot refers to a binding: which texture of the scene's TextureCache, how it
// is placed on the surface (a UV transform: KHR_texture_transform, MTL -o/-s) and wrapped. Two
// materials placing one file differently have two bindings of one texture.
#pragma once
#include <cmath>

#include "core/image/texture_cache.h"
#include "core/math/vec.h"

namespace pt {

// KHR_texture_transform, in texture space (s right, t down: glTF's uv): st' = T R S st with
// T = translate(offset), R = [[cos r, sin r], [-sin r, cos r]] (rotation r in radians,
// counter-clockwise in the image as the extension defines it), S = scale.
struct UvTransform {
  Vec2f offset{0.0f, 0.0f};
  float rotation = 0.0f;
  Vec2f scale{1.0f, 1.0f};

  bool is_identity() const {
    return offset.x == 0 && offset.y == 0 && rotation == 0 && scale.x == 1 && scale.y == 1;
  }
  bool operator==(const UvTransform& o) const {
    return offset.x == o.offset.x && offset.y == o.offset.y && rotation == o.rotation && scale.x == o.scale.x &&
           scale.y == o.scale.y;
  }
  // The linear part alone (for the footprint's derivatives).
  Vec2f apply_linear(Vec2f d) const {
    float c = std::cos(rotation), s = std::sin(rotation);
    Vec2f k{d.x * scale.x, d.y * scale.y};
    return {c * k.x + s * k.y, -s * k.x + c * k.y};
  }
  Vec2f apply(Vec2f st) const { return apply_linear(st) + offset; }
};

// A UvTransform as the affine map it is, worked out once: st' = (m00 s + m01 t, m10 s + m11 t) + offset.
struct UvMatrix {
  float m00 = 1, m01 = 0, m10 = 0, m11 = 1;
  Vec2f offset{0.0f, 0.0f};
  bool identity = true;

  UvMatrix() = default;
  explicit UvMatrix(const UvTransform& t) : offset(t.offset), identity(t.is_identity()) {
    const float c = std::cos(t.rotation), s = std::sin(t.rotation);
    m00 = c * t.scale.x, m01 = s * t.scale.y, m10 = -s * t.scale.x, m11 = c * t.scale.y;
  }
  Vec2f linear(Vec2f d) const { return identity ? d : Vec2f(m00 * d.x + m01 * d.y, m10 * d.x + m11 * d.y); }
  Vec2f apply(Vec2f st) const { return identity ? st : linear(st) + offset; }
};

struct TextureBinding {
  int texture = -1;  // in the scene's TextureCache
  UvTransform transform;
  TextureWrap wrap_s = TextureWrap::kRepeat, wrap_t = TextureWrap::kRepeat;
  UvMatrix matrix;  // transform, worked out (set by the loader that registers the binding)

  bool operator==(const TextureBinding& o) const {
    return texture == o.texture && transform == o.transform && wrap_s == o.wrap_s && wrap_t == o.wrap_t;
  }
};

}  // namespace pt
