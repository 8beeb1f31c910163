// Float image buffers and their files: EXR (linear float, extra channels, metadata) and 8-bit
// PNG/JPEG (exposure and the sRGB transfer), read and written through OpenImageIO.
#pragma once
#include <cstdint>
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
  // Empty, or one flag per channel: the channel's floats hold the bits of a uint32 (exact counts,
  // the halves of a double), written as an EXR UINT channel and read back bit for bit. A split
  // render's parts carry their double sums this way (renderer/farm/part_file.h).
  std::vector<bool> uint32_bits;

  Image() = default;
  Image(int w, int h, std::vector<std::string> names)
      : width(w), height(h), channels(std::move(names)),
        pixels(static_cast<size_t>(w) * h * channels.size(), 0.0f) {}
  size_t channel_count() const { return channels.size(); }
  bool is_uint32(size_t c) const { return c < uint32_bits.size() && uint32_bits[c]; }
  float& at(int x, int y, int c) { return pixels[(static_cast<size_t>(y) * width + x) * channels.size() + c]; }
  float at(int x, int y, int c) const {
    return pixels[(static_cast<size_t>(y) * width + x) * channels.size() + c];
  }
};

struct WriteOptions {
  float exposure = 0.0f;  // stops, applied to 8-bit outputs only
  std::string compression = "zip";  // EXR compression (OpenImageIO's name: zip, rle, none, ...)
};

// Encodes in memory, then writes through OutputFile (core/util/output_file.h): every write checked,
// a temporary beside `path` renamed over it only when complete, nothing but a regular file
// replaced. The format follows the extension (.exr, .png, .jpg, .hdr ...). Throws pt::Error.
void write_image(const std::string& path, const Image& image, const WriteOptions& options = {});

// The largest image read (textures, environment maps, references, parts): 16384x8192 pixels, the
// largest common HDR environment map (1.5 GiB as float RGB), with at most 64 channels. A header
// that claims more is refused before anything is allocated for it, and memory is committed only
// as rows of pixels are read.
constexpr int64_t kMaxImagePixels = int64_t(16384) * 8192;
constexpr int kMaxImageSide = 65536;
constexpr int kMaxImageChannels = 64;

// Reads any image OpenImageIO knows; 8- and 16-bit integer files are taken as sRGB-encoded and
// linearised. An EXR's UINT channels come back as their bits (Image::uint32_bits). Only regular
// files are read. Throws pt::Error naming the file.
Image read_image(const std::string& path);
// Only the header: size, channel names and string metadata, no pixels (Image::pixels is empty).
Image read_image_header(const std::string& path);
// The whole image as a Texture (an environment map). Surface textures go through the TextureCache
// instead (core/image/texture_cache.h).
std::shared_ptr<Texture> read_texture(const std::string& path);

float srgb_encode(float linear);
float srgb_decode(float encoded);
// Decodes values[0], values[stride], ... (n values in all, each an 8- or 16-bit integer normalised
// to [0, 1]) in place, by table.
void srgb_decode_integers(float* values, size_t n, size_t stride, bool sixteen_bit);
bool is_8bit_format(const std::string& path);

}  // namespace pt
