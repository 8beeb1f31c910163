// The camera rays of an image: through a point of a pixel, with the ray differentials textured
// scenes filter by. The renderer's samples and the extra views of emitter_edges.h make theirs here.
#pragma once
#include "core/scene/camera.h"
#include "core/scene/scene.h"

namespace pt {

class CameraRays {
 public:
  // `spp` samples per pixel: the footprint is one stratum of them wide (Camera::footprint_strata).
  CameraRays(const Camera& camera, int width, int height, int spp, bool differentials)
      : basis_(camera.basis(static_cast<float>(width) / height)),
        width_(width),
        height_(height),
        pixel_step_{1.0f / static_cast<float>(width), 1.0f / static_cast<float>(height)},
        strata_(Camera::footprint_strata(spp)),
        cell_(1.0f / static_cast<float>(strata_)),
        differentials_(differentials) {}

  // The ray through (x + jitter.x, y + jitter.y), jitter in [0, 1)^2. Ray differentials one
  // stratum wide and centred on the sample's stratum, for filtered texture lookups, where asked.
  Ray operator()(int x, int y, Vec2f jitter) const {
    // By the pixel's size, not divided by the image's: a division's latency is on the way to every
    // camera ray's first intersection.
    Vec2f film{(static_cast<float>(x) + jitter.x) * pixel_step_.x, (static_cast<float>(y) + jitter.y) * pixel_step_.y};
    // Both returns are the callee's prvalue, so the ray (some 100 bytes) is made in place: a
    // named copy here cost a tenth of the camera rays' instructions.
    if (!differentials_) return Camera::ray(basis_, film);
    return Camera::ray(basis_, film, pixel_step_, cell_, Camera::stratum_centre(jitter, strata_));
  }

 private:
  Camera::Basis basis_;
  int width_, height_;
  Vec2f pixel_step_;
  int strata_;
  float cell_;  // 1 / strata_: the footprint's scale
  bool differentials_;
};

}  // namespace pt
