// TextureCache on OpenImageIO's TextureSystem (texture_cache.h): one private TextureSystem (and
// ImageCache) per scene, bounded by max_memory_MB; untiled files are cut into 64x64 tiles and
// unmipped files get their MIP levels made in the cache (autotile, automip), tiled and mipped files
// (`maketx` output) are read as they are.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagecache.h>
#include <OpenImageIO/texture.h>

#include <cstdio>
#include <mutex>
#include <vector>

#include "core/image/texture_module.h"
#include "core/util/error.h"

namespace pt {
namespace {

OIIO::TextureOpt::Wrap oiio_wrap(TextureWrap w) {
  switch (w) {
    case TextureWrap::kRepeat: return OIIO::TextureOpt::WrapPeriodic;
    case TextureWrap::kClamp: return OIIO::TextureOpt::WrapClamp;
    case TextureWrap::kMirror: return OIIO::TextureOpt::WrapMirror;
    case TextureWrap::kBlack: return OIIO::TextureOpt::WrapBlack;
  }
  return OIIO::TextureOpt::WrapPeriodic;
}

class OiioTextureCache final : public TextureCache {
 public:
  explicit OiioTextureCache(const TextureCacheOptions& options) : options_(options) {
    // A private system: its cache bound and options are this scene's, not a process-wide default.
    ts_ = OIIO::TextureSystem::create(false);
    ts_->attribute("max_memory_MB", options.max_memory_mb);
    ts_->attribute("autotile", 64);
    ts_->attribute("automip", 1);
    ts_->attribute("accept_untiled", 1);
    ts_->attribute("accept_unmipped", 1);
    // Each open untiled file may hold a decoded copy inside its reader (PNG, JPEG): few stay open.
    ts_->attribute("max_open_files", 16);
    ts_->attribute("failure_retries", 0);
  }
  ~OiioTextureCache() override { OIIO::TextureSystem::destroy(ts_, true); }

  int add(const std::string& path, TextureEncoding encoding) override {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t i = 0; i < files_.size(); ++i) {
      if (!files_[i].bytes && files_[i].info.path == path && files_[i].info.encoding == encoding) return static_cast<int>(i);
    }
    Image header = check_image(path);  // throws pt::Error naming the file
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path);
    if (!in) throw Error(path, "cannot read image: " + OIIO::geterror());
    File f;
    f.info = describe(path, encoding, header, in.get());
    TextureSource source;
    source.path = path;
    source.decode = encoding == TextureEncoding::kColour && is_integer(in->spec());
    in->close();
    // Files the cache reads as they are keep their own name (and so their tiles and MIP levels).
    register_file(f, source.decode ? make_cache_name(source, path) : path, source.decode, path);
    return static_cast<int>(files_.size() - 1);
  }

  int add_memory(const std::string& name, const std::string& format, std::vector<unsigned char> bytes,
                 TextureEncoding encoding) override {
    std::lock_guard<std::mutex> lock(mutex_);
    Image header = check_image_memory(name, format, bytes);  // throws pt::Error naming the image
    File f;
    f.bytes = std::make_unique<std::vector<unsigned char>>(std::move(bytes));
    TextureSource source;
    source.bytes = f.bytes.get();
    source.format = format;
    {
      OIIO::Filesystem::IOMemReader reader(f.bytes->data(), f.bytes->size());
      OIIO::ImageSpec config;
      OIIO::Filesystem::IOProxy* proxy = &reader;
      config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
      auto in = OIIO::ImageInput::open("embedded." + format, &config);
      if (!in) throw Error(name, "cannot read the embedded " + format + " image: " + OIIO::geterror());
      f.info = describe(name, encoding, header, in.get());
      source.decode = encoding == TextureEncoding::kColour && is_integer(in->spec());
    }
    register_file(f, make_cache_name(source, name), true, name);
    return static_cast<int>(files_.size() - 1);
  }

  const TextureFileInfo& info(int id) const override { return files_[id].info; }
  int count() const override { return static_cast<int>(files_.size()); }

  Spectrum lookup(int id, const TextureQuery& q) const override {
    const File& f = files_[id];
    // One channel is grey; two are grey and alpha.
    const int nc = f.info.channels >= 3 ? 3 : 1;
    float out[3] = {0, 0, 0};
    if (!texture(f, q, 0, nc, out)) return Spectrum(0.0f);
    if (nc < 3) return Spectrum(out[0]);
    return {out[0], out[1], out[2]};
  }

  float lookup_alpha(int id, const TextureQuery& q) const override {
    const File& f = files_[id];
    const int channel = f.info.channels == 4 ? 3 : f.info.channels == 2 ? 1 : -1;
    if (channel < 0) return 1.0f;
    float out = 1.0f;
    if (!texture(f, q, channel, 1, &out)) return 1.0f;
    return out;
  }

  std::string summary() const override {
    int64_t memory = 0;
    int tiles = 0, files = 0;
    ts_->imagecache()->getattribute("stat:cache_memory_used", OIIO::TypeDesc::INT64, &memory);
    ts_->imagecache()->getattribute("stat:tiles_created", tiles);
    ts_->imagecache()->getattribute("stat:open_files_created", files);
    char buf[160];
    std::snprintf(buf, sizeof buf, "texture cache: %.0f MB in use (bound %.0f MB), %d tiles read, %d file opens",
                  static_cast<double>(memory) / (1 << 20), static_cast<double>(options_.max_memory_mb), tiles, files);
    return buf;
  }

 private:
  struct File {
    TextureFileInfo info;
    OIIO::TextureSystem::TextureHandle* handle = nullptr;
    std::unique_ptr<std::vector<unsigned char>> bytes;  // an image held in memory, else null
  };

  static bool is_integer(const OIIO::ImageSpec& spec) {
    return spec.format.basetype == OIIO::TypeDesc::UINT8 || spec.format.basetype == OIIO::TypeDesc::UINT16;
  }
  static TextureFileInfo describe(const std::string& path, TextureEncoding encoding, const Image& header,
                                  OIIO::ImageInput* in) {
    TextureFileInfo info;
    info.path = path;
    info.encoding = encoding;
    info.width = header.width;
    info.height = header.height;
    info.channels = static_cast<int>(header.channel_count());
    int levels = 1;
    while (in->seek_subimage(0, levels)) ++levels;
    info.mip_levels = levels;
    return info;
  }
  bool texture(const File& f, const TextureQuery& q, int first, int channels, float* out) const {
    OIIO::TextureOpt opt;
    opt.firstchannel = first;
    opt.swrap = oiio_wrap(q.wrap_s);
    opt.twrap = oiio_wrap(q.wrap_t);
    // Bilinear within a level in both modes: magnified textures then look as they did before the
    // TextureSystem (its default, bicubic when magnifying, would change every close-up), and only
    // minification differs: filtered over the footprint, or point-sampled from level 0.
    opt.interpmode = OIIO::TextureOpt::InterpBilinear;
    float dsdx = q.dsdx, dtdx = q.dtdx, dsdy = q.dsdy, dtdy = q.dtdy;
    if (options_.filter == TextureFilter::kBilinear) {
      opt.mipmode = OIIO::TextureOpt::MipModeNoMIP;
      dsdx = dtdx = dsdy = dtdy = 0.0f;
    } else {
      opt.mipmode = OIIO::TextureOpt::MipModeAniso;
    }
    OIIO::TextureSystem::Perthread* thread = ts_->get_perthread_info();
    if (!ts_->texture(f.handle, thread, opt, q.s, q.t, dsdx, dtdx, dsdy, dtdy, channels, out)) {
      ts_->geterror();  // the file was checked at load; a read failing now shows as black
      return false;
    }
    return true;
  }
  // custom: opened through pt's reader (texture_input.cpp) under `name`.
  void register_file(File& f, const std::string& name, bool custom, const std::string& shown) {
    const OIIO::ustring key(name);
    if (custom) ts_->imagecache()->add_file(key, &make_cache_input);
    f.handle = ts_->get_texture_handle(key);
    if (!f.handle) throw Error(shown, "the texture system cannot open it: " + ts_->geterror());
    files_.push_back(std::move(f));
  }
  TextureCacheOptions options_;
  OIIO::TextureSystem* ts_ = nullptr;
  std::vector<File> files_;  // filled while loading, read only while rendering
  std::mutex mutex_;
};

}  // namespace

std::shared_ptr<TextureCache> make_oiio_texture_cache(const TextureCacheOptions& options) {
  return std::make_shared<OiioTextureCache>(options);
}

}  // namespace pt
