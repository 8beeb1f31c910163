#include "core/image/tonemap.h"

#include <algorithm>
#include <cmath>

namespace pt {
namespace {

float aces(float x) {
  return (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
}

float hable(float x) {
  constexpr float A = 0.15f, B = 0.50f, C = 0.10f, D = 0.20f, E = 0.02f, F = 0.30f;
  return (x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F) - E / F;
}

}  // namespace

float tonemap(float x, Tonemap curve) {
  if (!(x > 0.0f)) return 0.0f;  // negative, zero or NaN
  float y = x;
  switch (curve) {
    case Tonemap::kClip: break;
    case Tonemap::kAces: y = aces(x); break;
    case Tonemap::kFilmic: {
      static const float white = hable(11.2f);
      y = std::isinf(x) ? 1.0f : hable(2.0f * x) / white;
      break;
    }
  }
  if (std::isnan(y)) y = 1.0f;  // inf / inf in the rational curves: infinitely bright is white
  return std::clamp(y, 0.0f, 1.0f);
}

void apply_tonemap(Image& image, Tonemap curve, float exposure_stops) {
  const int keep = std::min<int>(3, static_cast<int>(image.channel_count()));
  Image out(image.width, image.height, std::vector<std::string>(image.channels.begin(), image.channels.begin() + keep));
  out.metadata = std::move(image.metadata);
  const float scale = std::exp2(exposure_stops);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < keep; ++c) out.at(x, y, c) = tonemap(image.at(x, y, c) * scale, curve);
    }
  }
  image = std::move(out);
}

}  // namespace pt
