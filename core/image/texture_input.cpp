// The reader through which OpenImageIO's image cache sees a texture it cannot read by itself as
// stored: a colour texture stored as integers (its colour channels sRGB-decoded, as half floats:
// texture_cache.h says why the decoding happens here), or an image held in memory (a glTF's embedded
// PNG or JPEG, decoded from its bytes). It serves every subimage and MIP level of the inner file;
// the cache asks for tiles (or scanlines, for untiled files) as lookups need them, so only those are
// decoded.
#include <OpenImageIO/filesystem.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <vector>

#include "core/image/texture_module.h"

namespace pt {
namespace {

class CacheInput final : public OIIO::ImageInput {
 public:
  const char* format_name() const override { return "pt-texture"; }
  int supports(OIIO::string_view) const override { return 0; }

  bool open(const std::string& name, OIIO::ImageSpec& newspec) override {
    std::lock_guard<std::mutex> lock(mutex_);
    TextureSource source;
    if (!parse_cache_name(name, source)) {
      errorf("%s: not a texture pt registered", name);
      return false;
    }
    decode_ = source.decode;
    if (source.bytes) {
      memory_ = std::make_unique<OIIO::Filesystem::IOMemReader>(source.bytes->data(), source.bytes->size());
      OIIO::ImageSpec inner_config;
      OIIO::Filesystem::IOProxy* proxy = memory_.get();
      inner_config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
      inner_ = OIIO::ImageInput::open("embedded." + source.format, &inner_config);
    } else {
      inner_ = OIIO::ImageInput::open(source.path);
    }
    if (!inner_) {
      errorf("%s", OIIO::geterror());
      return false;
    }
    m_spec = served_spec(inner_->spec());
    newspec = m_spec;
    return true;
  }
  bool close() override {
    std::lock_guard<std::mutex> lock(mutex_);
    inner_.reset();
    memory_.reset();
    return true;
  }
  int current_subimage() const override { return inner_ ? inner_->current_subimage() : 0; }
  int current_miplevel() const override { return inner_ ? inner_->current_miplevel() : 0; }
  bool seek_subimage(int subimage, int miplevel) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!inner_ || !inner_->seek_subimage(subimage, miplevel)) return false;
    m_spec = served_spec(inner_->spec());
    return true;
  }

  bool read_native_scanline(int subimage, int miplevel, int y, int z, void* data) override {
    return read_native_scanlines(subimage, miplevel, y, y + 1, z, data);
  }
  bool read_native_scanlines(int subimage, int miplevel, int ybegin, int yend, int z, void* data) override {
    std::lock_guard<std::mutex> lock(mutex_);
    OIIO::ImageSpec spec = inner_->spec_dimensions(subimage, miplevel);
    const int nc = inner_->spec().nchannels;
    std::vector<float> buffer(static_cast<size_t>(spec.width) * (yend - ybegin) * nc);
    if (!inner_->read_scanlines(subimage, miplevel, ybegin, yend, z, 0, nc, OIIO::TypeDesc::FLOAT, buffer.data())) {
      errorf("%s", inner_->geterror());
      return false;
    }
    return convert(buffer.data(), buffer.size(), nc, data);
  }
  bool read_native_tile(int subimage, int miplevel, int x, int y, int z, void* data) override {
    std::lock_guard<std::mutex> lock(mutex_);
    OIIO::ImageSpec spec = inner_->spec_dimensions(subimage, miplevel);
    const int nc = inner_->spec().nchannels;
    const int tw = spec.tile_width, th = spec.tile_height, td = std::max(1, spec.tile_depth);
    // A tile at the image's edge is read clipped and laid out in a whole tile, as native tiles are.
    const int xend = std::min(x + tw, spec.x + spec.width), yend = std::min(y + th, spec.y + spec.height);
    const int zend = std::min(z + td, spec.z + std::max(1, spec.depth));
    const int w = xend - x, h = yend - y, d = zend - z;
    std::vector<float> buffer(static_cast<size_t>(w) * h * d * nc);
    if (!inner_->read_tiles(subimage, miplevel, x, xend, y, yend, z, zend, 0, nc, OIIO::TypeDesc::FLOAT, buffer.data())) {
      errorf("%s", inner_->geterror());
      return false;
    }
    std::vector<float> tile(static_cast<size_t>(tw) * th * td * nc, 0.0f);
    for (int k = 0; k < d; ++k) {
      for (int j = 0; j < h; ++j) {
        std::copy_n(&buffer[((static_cast<size_t>(k) * h + j) * w) * nc], static_cast<size_t>(w) * nc,
                    &tile[((static_cast<size_t>(k) * th + j) * tw) * nc]);
      }
    }
    return convert(tile.data(), tile.size(), nc, data);
  }

 private:
  // Half floats: as precise as 8- and 16-bit sRGB values need once linear (the darkest 8-bit step,
  // 1/3295, is well inside half's range), at 2 bytes a channel in the cache.
  static OIIO::ImageSpec served_spec(const OIIO::ImageSpec& file) {
    OIIO::ImageSpec spec = file;
    spec.set_format(OIIO::TypeDesc::FLOAT);
    spec.channelformats.clear();
    spec.attribute("oiio:ColorSpace", "Linear");
    return spec;
  }
  // The colour channels (the first three) are decoded where asked; a fourth (alpha) is linear
  // already. Then to half floats, the format the spec promised.
  bool convert(float* values, size_t n, int nc, void* out) const {
    if (decode_) {
      const bool sixteen = inner_->spec().format.basetype == OIIO::TypeDesc::UINT16;
      for (int c = 0; c < std::min(3, nc); ++c) srgb_decode_integers(values + c, n - c, nc, sixteen);
    }
    return OIIO::convert_pixel_values(OIIO::TypeDesc::FLOAT, values, OIIO::TypeDesc::FLOAT, out, static_cast<int>(n));
  }

  std::unique_ptr<OIIO::Filesystem::IOMemReader> memory_;
  std::unique_ptr<OIIO::ImageInput> inner_;
  bool decode_ = false;
  std::mutex mutex_;
};

constexpr const char* kPrefix = "pt-texture:";

}  // namespace

// "pt-texture:<d|l>:<bytes address in hex, or 0>:<format>:<path or display name>". The address is
// only ever parsed back inside the process that wrote it, from names this cache registered.
std::string make_cache_name(const TextureSource& source, const std::string& display_name) {
  char address[32];
  std::snprintf(address, sizeof address, "%llx",
                static_cast<unsigned long long>(reinterpret_cast<uintptr_t>(source.bytes)));
  return std::string(kPrefix) + (source.decode ? "d:" : "l:") + address + ":" + source.format + ":" +
         (source.bytes ? display_name : source.path);
}

bool parse_cache_name(const std::string& name, TextureSource& source) {
  const std::string prefix = kPrefix;
  if (name.rfind(prefix, 0) != 0 || name.size() < prefix.size() + 2) return false;
  size_t at = prefix.size();
  source.decode = name[at] == 'd';
  size_t colon1 = name.find(':', at + 2);
  if (colon1 == std::string::npos) return false;
  size_t colon2 = name.find(':', colon1 + 1);
  if (colon2 == std::string::npos) return false;
  unsigned long long address = std::strtoull(name.substr(at + 2, colon1 - at - 2).c_str(), nullptr, 16);
  source.bytes = reinterpret_cast<const std::vector<unsigned char>*>(static_cast<uintptr_t>(address));
  source.format = name.substr(colon1 + 1, colon2 - colon1 - 1);
  source.path = source.bytes ? std::string() : name.substr(colon2 + 1);
  return true;
}

OIIO::ImageInput* make_cache_input() { return new CacheInput(); }

}  // namespace pt
