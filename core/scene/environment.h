// Light arriving from infinitely far away: a constant radiance or a lat-long image.
//
// Orientation of a lat-long image (also in scenes/README.md): +y is up; the top row of the image
// looks straight up, the bottom row straight down; the centre column (u = 0.5) looks toward -z and
// u grows toward +x (u = 0.75 looks toward +x). `rotation` turns the map about +y by that many
// degrees (right-handed). Images are importance-sampled with a sin(theta)-weighted piecewise-
// constant 2D distribution (PBRT 3rd ed., 14.2.4) over the bilinearly filtered radiance.
#pragma once
#include <memory>

#include "core/math/distribution.h"
#include "core/math/sampling.h"
#include "core/image/texture.h"

namespace pt {

class Environment {
 public:
  Environment() = default;
  explicit Environment(Spectrum radiance) : constant_(radiance) {}
  Environment(std::shared_ptr<const Texture> image, float scale, float rotation_degrees)
      : image_(std::move(image)), scale_(scale), rotation_(rotation_degrees * kPi / 180.0f) {
    // eval() filters bilinearly, so the radiance inside a texel's cell depends on its neighbours
    // too; a texel's weight is the integral of that filtered radiance over its cell: the
    // separable kernel (1/8, 3/4, 1/8), wrapping in u and clamping at the poles as lookup() does
    // (pbrt-v4 likewise builds its sampling distribution from the filtered image). Weighting by the
    // texel alone left the ring of cells around a small bright source (a sun) with up to half its
    // radiance but the sky's pdf: BSDF-sampled hits there were fireflies, and where such a texel
    // is black, light sampling alone (strategy light) never reached it, and so was biased.
    int w = image_->width, h = image_->height;
    std::vector<float> lum(static_cast<size_t>(w) * h), across(lum.size()), weights(lum.size());
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) lum[static_cast<size_t>(y) * w + x] = luminance(image_->texel(x, y));
    }
    for (int y = 0; y < h; ++y) {
      const float* row = &lum[static_cast<size_t>(y) * w];
      for (int x = 0; x < w; ++x) {
        across[static_cast<size_t>(y) * w + x] = 0.75f * row[x] + 0.125f * (row[(x + w - 1) % w] + row[(x + 1) % w]);
      }
    }
    for (int y = 0; y < h; ++y) {
      float sin_theta = std::sin(kPi * (y + 0.5f) / h);
      const float* above = &across[static_cast<size_t>(std::max(y - 1, 0)) * w];
      const float* here = &across[static_cast<size_t>(y) * w];
      const float* below = &across[static_cast<size_t>(std::min(y + 1, h - 1)) * w];
      for (int x = 0; x < w; ++x) {
        weights[static_cast<size_t>(y) * w + x] = (0.75f * here[x] + 0.125f * (above[x] + below[x])) * sin_theta;
      }
    }
    distribution_ = Distribution2D(weights, w, h);
  }

  bool has_image() const { return image_ != nullptr; }
  const Texture* image() const { return image_.get(); }
  Spectrum constant() const { return constant_; }
  float scale() const { return scale_; }
  float rotation_degrees() const { return rotation_ * 180.0f / kPi; }
  Spectrum average() const { return image_ ? image_->average() * scale_ : constant_; }

  Spectrum eval(const Vec3f& dir) const {
    if (!image_) return constant_;
    Vec2f uv = direction_to_uv(dir);
    return image_->lookup({uv.x, 1.0f - uv.y}, /*clamp_v=*/true) * scale_;
  }

  // Samples a direction; pdf is per unit solid angle.
  Vec3f sample(Vec2f u, float* pdf) const {
    if (!image_) {
      *pdf = uniform_sphere_pdf();
      return square_to_uniform_sphere(u);
    }
    float pdf_uv;
    Vec2f uv = distribution_.sample(u, &pdf_uv);
    Vec3f dir = uv_to_direction(uv);
    // The density of the direction as pdf() sees it: on a texel edge the round trip uv -> dir ->
    // uv can land in the neighbour, and MIS needs the two to agree exactly.
    *pdf = pdf_uv > 0 ? this->pdf(dir) : 0.0f;
    return dir;
  }
  float pdf(const Vec3f& dir) const {
    if (!image_) return uniform_sphere_pdf();
    Vec2f uv = direction_to_uv(dir);
    float sin_theta = std::sin(kPi * uv.y);
    return sin_theta > 0 ? distribution_.pdf(uv) / (2.0f * kPi * kPi * sin_theta) : 0.0f;
  }

  // uv in [0,1)^2 with v = 0 at the top row (straight up).
  Vec2f direction_to_uv(const Vec3f& d) const {
    // A right-handed turn about +y moves -z toward -x, i.e. lowers phi: a texel drawn at phi0
    // appears at phi0 - rotation, so the lookup adds the rotation back.
    float phi = std::atan2(d.x, -d.z) + rotation_;
    float u = 0.5f + phi / (2.0f * kPi);
    u -= std::floor(u);
    float v = std::acos(std::clamp(d.y, -1.0f, 1.0f)) * kInvPi;
    return {u, v};
  }
  Vec3f uv_to_direction(Vec2f uv) const {
    float phi = (uv.x - 0.5f) * 2.0f * kPi - rotation_;
    float theta = uv.y * kPi;
    float st = std::sin(theta);
    return {st * std::sin(phi), std::cos(theta), -st * std::cos(phi)};
  }

 private:
  Spectrum constant_{0.0f};
  std::shared_ptr<const Texture> image_;
  float scale_ = 1.0f;
  float rotation_ = 0.0f;
  Distribution2D distribution_;
};

}  // namespace pt
