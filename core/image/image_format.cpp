// image.h's functions that need no image library: the sRGB curve and what an extension means. In
// pt_core itself, so that asking them never loads OpenImageIO (core/image/image_module.h).
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/image/image.h"
#include "core/util/file_extension.h"

namespace pt {

float srgb_encode(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}
float srgb_decode(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

void srgb_decode_integers(float* values, size_t n, size_t stride, bool sixteen_bit) {
  // A table per integer depth: every 8- or 16-bit value decoded once (std::pow costs ~20 ns, and a
  // 4096^2 texture has 50 M of them).
  static const std::vector<float> table8 = [] {
    std::vector<float> t(256);
    for (int i = 0; i < 256; ++i) t[i] = srgb_decode(i / 255.0f);
    return t;
  }();
  static const std::vector<float> table16 = [] {
    std::vector<float> t(65536);
    for (int i = 0; i < 65536; ++i) t[i] = srgb_decode(i / 65535.0f);
    return t;
  }();
  const std::vector<float>& table = sixteen_bit ? table16 : table8;
  const float scale = sixteen_bit ? 65535.0f : 255.0f;
  for (size_t i = 0; i < n; i += stride) {
    const float v = std::clamp(values[i], 0.0f, 1.0f) * scale + 0.5f;
    values[i] = table[static_cast<size_t>(v)];
  }
}

bool is_8bit_format(const std::string& path) {
  std::string ext = lower_extension(path);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tga";
}

}  // namespace pt
