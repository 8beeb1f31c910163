// Pinhole camera (position, look-at point, up vector and vertical field of view) or orthographic
// (parallel rays along the view direction over a film ortho_height scene units tall).
#pragma once
#include <algorithm>
#include <cmath>

#include "core/geometry/ray.h"
#include "core/math/bbox.h"
#include "core/math/frame.h"

namespace pt {

struct Camera {
  Vec3f position{0, 0, 5};
  Vec3f look_at{0, 0, 0};
  Vec3f up{0, 1, 0};
  float vfov_degrees = 40.0f;
  float ortho_height = 0.0f;  // > 0: orthographic, the film's height in scene units (vfov unused)

  bool orthographic() const { return ortho_height > 0.0f; }

  // Film coordinates in [0,1)^2, (0,0) at the top-left of the image. Perspective: rays from
  // `origin` toward forward + right x + down y. Orthographic: rays along `forward` from
  // origin + right x + down y (origin is then the film's top-left corner).
  struct Basis {
    Vec3f origin, forward, right, down;
    bool ortho = false;
  };
  Basis basis(float aspect) const {
    Vec3f f = normalize(look_at - position);
    Vec3f r = normalize(cross(f, up));
    Vec3f u = cross(r, f);
    if (orthographic()) {
      float half_h = 0.5f * ortho_height, half_w = half_h * aspect;
      return {position - r * half_w + u * half_h, f, r * (2 * half_w), u * (-2 * half_h), true};
    }
    float half_h = std::tan(0.5f * vfov_degrees * kPi / 180.0f);
    float half_w = half_h * aspect;
    return {position, f - r * half_w + u * half_h, r * (2 * half_w), u * (-2 * half_h), false};
  }
  static Ray ray(const Basis& b, Vec2f film) {
    Ray r;
    if (b.ortho) {
      r.o = b.origin + b.right * film.x + b.down * film.y;
      r.d = b.forward;
      return r;
    }
    r.o = b.origin;
    const Vec3f u = b.forward + b.right * film.x + b.down * film.y;
    r.d = u * (1.0f / length(u));  // one division, not three
    return r;
  }
  // The side of the finest square grid a pixel's `spp` samples stratify (a (0, 2)-net of 2^k points
  // has one point in each cell of a 2^(k/2)-square grid), at most 8: the footprint of a camera ray
  // is one cell (1 / strata of a pixel) and is centred on the cell that holds the sample
  // (stratum_centre), so that each sample filters the texture over the part of the pixel it stands
  // for. Any sampler whose jitter is uniform over the pixel meets each cell as often as the others,
  // so a pixel's samples still average to the pixel's mean.
  static int footprint_strata(int spp) {
    int strata = 1;
    while (strata < 8 && 4 * strata * strata <= spp) strata *= 2;
    return strata;
  }
  // From the sample at `jitter` (in [0, 1)^2 over the pixel) to the centre of its cell of a
  // strata x strata grid, in cells (RayDifferential::centre).
  static Vec2f stratum_centre(Vec2f jitter, int strata) {
    const float n = static_cast<float>(strata);
    // j n >= 0, so truncation is the floor (std::floor is a call without SSE4.1).
    auto offset = [&](float j) { return static_cast<float>(std::min(static_cast<int>(j * n), strata - 1)) + 0.5f - j * n; };
    return {offset(jitter.x), offset(jitter.y)};
  }

  // The ray through `film` with its differentials: the rays through the film points `scale` pixels
  // (`pixel`, in film units) to the right and below (RayDifferential::scale). Perspective: their
  // directions d + dddx are those film points' directions divided by the ray's own length, not
  // normalised: a footprint meets the surface with the neighbouring ray's line, which its length
  // does not change (normalising them was 19M of the 160M instructions filtered lookups added on
  // the horizon, docs/textures.md).
  // `centre`: RayDifferential::centre.
  static Ray ray(const Basis& b, Vec2f film, Vec2f pixel, float scale, Vec2f centre = {}) {
    Ray r;
    if (b.ortho) {
      r = ray(b, film);
      r.diff.dodx = b.right * (pixel.x * scale);
      r.diff.dody = b.down * (pixel.y * scale);
    } else {
      const Vec3f u = b.forward + b.right * film.x + b.down * film.y;
      const float inv_len = 1.0f / length(u);
      r.o = b.origin;
      r.d = u * inv_len;  // as ray(b, film) makes it, bit for bit
      r.diff.dddx = b.right * (pixel.x * scale * inv_len);
      r.diff.dddy = b.down * (pixel.y * scale * inv_len);
    }
    r.diff.scale = scale;
    r.diff.centre = centre;
    return r;
  }

  // Looks at the centre of the bounds from direction `dir` (unit, from the centre toward the
  // camera), far enough that the bounding sphere fits the field of view `vfov` (degrees).
  static Camera framing(const BBox& bounds, float aspect, Vec3f dir = normalize(Vec3f(0.0f, 0.25f, 1.0f)),
                        Vec3f up = {0, 1, 0}, float vfov = 40.0f) {
    Camera c;
    c.up = up;
    c.vfov_degrees = vfov;
    Vec3f center = bounds.center();
    float radius = std::max(1e-3f, 0.5f * length(bounds.extent()));
    float half = 0.5f * c.vfov_degrees * kPi / 180.0f;
    if (aspect < 1.0f) half = std::atan(std::tan(half) * aspect);
    float distance = radius / std::sin(half);
    c.position = center + dir * distance;
    c.look_at = center;
    return c;
  }
};

}  // namespace pt
