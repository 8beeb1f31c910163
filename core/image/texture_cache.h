// Surface textures: registered once at load, looked up mip-mapped and filtered through OpenImageIO's
// TextureSystem, whose tile cache holds at most max_memory_mb of texels however many and however
// large the textures are. The TextureSystem lives in the image module (image_module.h), so a scene
// without textures never loads OpenImageIO; this is the interface pt_core sees.
//
// Colour and data: a colour texture stored as 8- or 16-bit integers is sRGB-encoded, and filtering
// encoded values then decoding them is wrong (a far checkerboard of 0 and 1 would average to
// decode(0.5) = 0.21, not 0.5). OpenImageIO 2.4's TextureSystem has no colour conversion on lookup,
// so such a texture is served to the cache through a decoding reader (texture_input.cpp): each tile
// is sRGB-decoded to half floats as the cache reads it, and the MIP levels the cache makes (automip)
// or reads (maketx output) are filtered in linear light. Only the tiles in use are ever decoded, so
// the cache bound holds; the cost is 2 bytes a channel in the cache instead of 1. Data textures
// (roughness, metallic, normals, heights) and float files are read as stored.
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/math/vec.h"
#include "core/util/names.h"

namespace pt {

enum class TextureWrap : uint8_t { kRepeat, kClamp, kMirror, kBlack };
inline constexpr NameTable<TextureWrap, 4> kTextureWrapNames{
    "texture wrap mode",
    {{{TextureWrap::kRepeat, "repeat"}, {TextureWrap::kClamp, "clamp"}, {TextureWrap::kMirror, "mirror"},
      {TextureWrap::kBlack, "black"}}}};

// kColour: integer files are sRGB-decoded (base colour, emission). kData: values as stored.
enum class TextureEncoding : uint8_t { kColour, kData };

// How lookups filter. kMipmap: anisotropic MIP-map filtering over the ray footprint (the default).
// kBilinear: the finest level only, bilinear, footprint ignored: what pt did before the
// TextureSystem, kept for comparisons (`--texture-filter bilinear`, docs/textures.md).
enum class TextureFilter : uint8_t { kMipmap, kBilinear };
inline constexpr NameTable<TextureFilter, 2> kTextureFilterNames{
    "texture filter", {{{TextureFilter::kMipmap, "mipmap"}, {TextureFilter::kBilinear, "bilinear"}}}};

struct TextureCacheOptions {
  float max_memory_mb = 512.0f;  // the tile cache's bound (OpenImageIO's max_memory_MB)
  TextureFilter filter = TextureFilter::kMipmap;
};

// A lookup in texture space: s to the right, t down (row 0 at t = 0, OpenImageIO's convention), and
// the footprint of one pixel's ray in it (zero: a point lookup at the finest level).
struct TextureQuery {
  float s = 0, t = 0;
  float dsdx = 0, dtdx = 0, dsdy = 0, dtdy = 0;
  // From (s, t) to the footprint's centre (RayDifferential::centre): filtered lookups are centred
  // there; bilinear ones (TextureFilter::kBilinear) read the point (s, t).
  float dsdc = 0, dtdc = 0;
  TextureWrap wrap_s = TextureWrap::kRepeat, wrap_t = TextureWrap::kRepeat;
  bool isotropic = false;  // filter over the footprint's longer axis alone (RayDifferential::rough)
};

struct TextureFileInfo {
  std::string path;  // the file, or the name of an image held in memory (a glTF's embedded image)
  TextureEncoding encoding = TextureEncoding::kColour;
  int width = 0, height = 0, channels = 0;
  int mip_levels = 1;  // in the file; 1 means the cache makes the others
  int held_first = -1;  // the finest MIP level pt holds (filtered without the TextureSystem); -1 none
  float mean[4] = {0, 0, 0, 0};  // the mean texel (RGBA, as decoded), where pt holds the 1x1 level
  bool has_mean = false;
};

class TextureCache {
 public:
  virtual ~TextureCache() = default;
  // Checks the file (a regular file within pt's image limits that decodes whole, every value
  // finite) and registers it; the same path and encoding give the same id. Throws pt::Error naming
  // the file.
  virtual int add(const std::string& path, TextureEncoding encoding) = 0;
  // The same for an encoded image file held in memory (PNG or JPEG bytes; `format` is the
  // extension of its kind, "png" or "jpg"), named `name` in messages. The cache keeps the encoded
  // bytes and decodes tiles from them as lookups need them.
  virtual int add_memory(const std::string& name, const std::string& format, std::vector<unsigned char> bytes,
                         TextureEncoding encoding) = 0;
  virtual const TextureFileInfo& info(int id) const = 0;
  virtual int count() const = 0;
  // The first three channels (one channel is returned as grey). Thread-safe: each thread has its
  // own OpenImageIO per-thread state.
  virtual Spectrum lookup(int id, const TextureQuery& query) const = 0;
  // The fourth channel (alpha) where the texture has one, else 1.
  virtual float lookup_alpha(int id, const TextureQuery& query) const = 0;
  // One line on the cache: memory peak, tiles read, files opened (OpenImageIO's statistics).
  virtual std::string summary() const = 0;
  // How lookups filter: a bilinear cache reads points, so rays need no differentials for it.
  virtual TextureFilter filter() const = 0;
  // Called once every texture is registered (the scene is built): the cache may then spend its
  // budget differently among them. Throws pt::Error naming a file that no longer reads.
  virtual void finish_loading() {}
};

// Opens the image module (and with it OpenImageIO). Throws pt::Error when it cannot be loaded.
std::shared_ptr<TextureCache> make_texture_cache(const TextureCacheOptions& options);

}  // namespace pt
