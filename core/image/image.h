// Float image buffers and their files: EXR (linear float, extra channels, metadata) and 8-bit
// PNG/JPEG (exposure and the sRGB transfer), read and written through OpenImageIO.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/image/texture.h"

namespace pt {

struct Image {
  int width = 0, height = 0;
  std::vector<std::string> channels;  // e.g. R, G, B, variance.R, ...
  std::vector<float> pixels;          // interleaved, row 0 at the top
  std::map<std::string, std::string> metadata;

  Image() = default;
  Image(int w, int h, std::vector<std::string> names)
      : width(w), height(h), channels(std::move(names)),
        pixels(static_cast<size_t>(w) * h * channels.size(), 0.0f) {}
  size_t channel_count() const { return channels.size(); }
  float& at(int x, int y, int c) { return pixels[(static_cast<size_t>(y) * width + x) * channels.size() + c]; }
  float at(int x, int y, int c) const {
    return pixels[(static_cast<size_t>(y) * width + x) * channels.size() + c];
  }
};

struct WriteOptions {
  float exposure = 0.0f;  // stops, applied to 8-bit outputs only
};

// Writes to a temporary file beside `path` and renames it, so a failure never leaves a partial file.
// The format follows the extension (.exr, .png, .jpg, .hdr ...). Throws pt::Error.
void write_image(const std::string& path, const Image& image, const WriteOptions& options = {});

// Reads any image OpenImageIO knows; 8- and 16-bit integer files are taken as sRGB-encoded and
// linearised. Throws pt::Error naming the file.
Image read_image(const std::string& path);
std::shared_ptr<Texture> read_texture(const std::string& path);

float srgb_encode(float linear);
float srgb_decode(float encoded);
bool is_8bit_format(const std::string& path);

}  // namespace pt
