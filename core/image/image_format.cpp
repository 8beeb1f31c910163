// image.h's functions that need no image library: the sRGB curve and what an extension means. In
// pt_core itself, so that asking them never loads OpenImageIO (core/image/image_module.h).
#include <algorithm>
#include <cmath>

#include "core/image/image.h"
#include "core/util/file_extension.h"

namespace pt {

float srgb_encode(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}
float srgb_decode(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

bool is_8bit_format(const std::string& path) {
  std::string ext = lower_extension(path);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".tga";
}

}  // namespace pt
