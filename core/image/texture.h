// An RGB image used as a surface texture or an environment map: bilinear lookup with wrapping.
#pragma once
#include <string>
#include <vector>

#include "core/math/vec.h"

namespace pt {

struct Texture {
  std::string path;
  int width = 0, height = 0;
  std::vector<Spectrum> texels;  // linear RGB, row 0 at the top of the image

  const Spectrum& texel(int x, int y) const { return texels[static_cast<size_t>(y) * width + x]; }

  // uv with v up (OBJ convention): v = 1 is the top row. Wraps in u; in v it wraps for surface
  // textures but clamps for lat-long maps (clamp_v), whose top and bottom rows are the two poles
  // and must not be blended into each other.
  Spectrum lookup(Vec2f uv, bool clamp_v = false) const {
    float fx = (uv.x - std::floor(uv.x)) * width - 0.5f;
    float v = clamp_v ? std::clamp(uv.y, 0.0f, 1.0f) : uv.y - std::floor(uv.y);
    float fy = (1.0f - v) * height - 0.5f;
    if (!std::isfinite(fx) || !std::isfinite(fy)) return texel(0, 0);
    float x0f = std::floor(fx), y0f = std::floor(fy);
    float ax = fx - x0f, ay = fy - y0f;
    int x0 = wrap(static_cast<int>(x0f), width), x1 = wrap(x0 + 1, width);
    int y0 = wrap(static_cast<int>(y0f), height), y1 = wrap(y0 + 1, height);
    if (clamp_v) {
      y0 = std::clamp(static_cast<int>(y0f), 0, height - 1);
      y1 = std::clamp(static_cast<int>(y0f) + 1, 0, height - 1);
    }
    return (texel(x0, y0) * (1 - ax) + texel(x1, y0) * ax) * (1 - ay) +
           (texel(x0, y1) * (1 - ax) + texel(x1, y1) * ax) * ay;
  }
  Spectrum average() const {
    double s[3] = {0, 0, 0};
    for (const Spectrum& t : texels) s[0] += t.x, s[1] += t.y, s[2] += t.z;
    double n = std::max<size_t>(1, texels.size());
    return {static_cast<float>(s[0] / n), static_cast<float>(s[1] / n), static_cast<float>(s[2] / n)};
  }

 private:
  static int wrap(int i, int n) {
    int r = i % n;
    return r < 0 ? r + n : r;
  }
};

}  // namespace pt
