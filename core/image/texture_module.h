// What the image module's texture code shares inside libpt_image_oiio.so (never included by
// pt_core): the check of a texture file, the reader the cache opens pt's own textures through, the
// TextureSystem-backed cache.
#pragma once
#include <OpenImageIO/imageio.h>

#include <memory>
#include <string>
#include <vector>

#include "core/image/coarse_levels.h"
#include "core/image/image.h"
#include "core/image/texture_cache.h"

namespace pt {

// A texture read through once at load (image_io.cpp): read_image's checks (size, channels, limits,
// every value finite) without keeping the pixels, and on the way the levels pt holds (CoarseLevels:
// the finest of at most `held_texels` texels and the coarser ones). `colour`: integer files are
// sRGB-decoded. The file, or encoded bytes held in memory (`format` "png" or "jpg", named `name`).
struct TextureScan {
  Image header;
  CoarseLevels levels;
  bool integer = false;  // stored as 8- or 16-bit integers
  int mip_levels = 1;    // in the file
};
TextureScan scan_texture(const std::string& path, bool colour, size_t held_texels);
TextureScan scan_texture_memory(const std::string& name, const std::string& format, const std::vector<unsigned char>& bytes,
                                bool colour, size_t held_texels);

// A texture the cache cannot open by itself as stored: an integer colour file to be sRGB-decoded,
// or an image held in memory. Its cache name says which (make_cache_name); the cache opens such
// names through make_cache_input (texture_input.cpp), which parses them back. The bytes of a memory
// image are owned by the TextureCache and outlive its TextureSystem.
struct TextureSource {
  bool decode = false;  // sRGB-decode the first three channels
  std::string path;     // a file, when bytes is null
  const std::vector<unsigned char>* bytes = nullptr;
  std::string format;   // of the bytes: "png", "jpg"
};
std::string make_cache_name(const TextureSource& source, const std::string& display_name);
bool parse_cache_name(const std::string& name, TextureSource& source);
OIIO::ImageInput* make_cache_input();

// The TextureSystem behind TextureCache (texture_system.cpp).
std::shared_ptr<TextureCache> make_oiio_texture_cache(const TextureCacheOptions& options);

}  // namespace pt
