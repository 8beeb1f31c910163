// TextureCache on OpenImageIO's TextureSystem (texture_cache.h): one private TextureSystem (and
// ImageCache) per scene, bounded by max_memory_MB; untiled files are cut into 64x64 tiles and
// unmipped files get their MIP levels made in the cache (autotile, automip), tiled and mipped files
// (`maketx` output) are read as they are.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagecache.h>
#include <OpenImageIO/texture.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <atomic>
#include <mutex>
#include <vector>

#include "core/image/coarse_levels.h"
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
    // An open PNG reader holds the whole decoded image (48 MB for 4096^2 RGB): few stay open.
    ts_->attribute("max_open_files", 8);
    ts_->attribute("failure_retries", 0);
  }
  ~OiioTextureCache() override { OIIO::TextureSystem::destroy(ts_, true); }

  int add(const std::string& path, TextureEncoding encoding) override {
    std::lock_guard<std::mutex> lock(mutex_);
    for (size_t i = 0; i < files_.size(); ++i) {
      if (!files_[i].bytes && files_[i].info.path == path && files_[i].info.encoding == encoding) return static_cast<int>(i);
    }
    const bool colour = encoding == TextureEncoding::kColour;
    TextureScan scan = scan_texture(path, colour, held_texels());  // throws pt::Error naming the file
    File f;
    TextureSource source;
    source.path = path;
    source.decode = colour && scan.integer;
    // Files the cache reads as they are keep their own name (and so their tiles and MIP levels).
    register_file(f, path, encoding, scan, source.decode ? make_cache_name(source, path) : path, source.decode);
    return static_cast<int>(files_.size() - 1);
  }

  int add_memory(const std::string& name, const std::string& format, std::vector<unsigned char> bytes,
                 TextureEncoding encoding) override {
    std::lock_guard<std::mutex> lock(mutex_);
    const bool colour = encoding == TextureEncoding::kColour;
    TextureScan scan = scan_texture_memory(name, format, bytes, colour, held_texels());  // throws pt::Error naming it
    File f;
    f.bytes = std::make_unique<std::vector<unsigned char>>(std::move(bytes));
    f.format = format;
    TextureSource source;
    source.bytes = f.bytes.get();
    source.format = format;
    source.decode = colour && scan.integer;
    register_file(f, name, encoding, scan, make_cache_name(source, name), true);
    return static_cast<int>(files_.size() - 1);
  }

  const TextureFileInfo& info(int id) const override { return files_[id].info; }
  int count() const override { return static_cast<int>(files_.size()); }

  Spectrum lookup(int id, const TextureQuery& q) const override {
    const File& f = files_[id];
    // One channel is grey; two are grey and alpha.
    float held[4];
    if (f.coarse.lookup(q, options_.filter == TextureFilter::kMipmap, held)) return {held[0], held[1], held[2]};
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
    float held[4];
    if (f.coarse.lookup(q, options_.filter == TextureFilter::kMipmap, held)) return held[3];
    float out = 1.0f;
    if (!texture(f, q, channel, 1, &out)) return 1.0f;
    return out;
  }

  TextureFilter filter() const override { return options_.filter; }

  // The first pass held at most kHeldTexels of each texture, not knowing how many would follow. Now
  // that all are known: every texture whole where all fit whole in the bound, else each up to the
  // largest size cap at which all fit in held_budget. A few textures of 1K-4K, as an asset brings,
  // are then filtered by pt whole, with no call into the TextureSystem (100 ns each; a 4096^2
  // floor to the horizon took 4x the time of a 64^2 one per pass), while a wall of 64 textures of
  // 4096^2 keeps 512^2. The files that gain levels are read once more.
  void finish_loading() override {
    std::lock_guard<std::mutex> lock(mutex_);
    auto total_at = [&](size_t texels) {
      double total = 0;
      for (const File& f : files_) {
        total += static_cast<double>(LevelBuilder::held_bytes(f.info.width, f.info.height,
                                                              LevelBuilder::first_level(f.info.width, f.info.height, texels)));
      }
      return total;
    };
    size_t cap = 0;
    if (total_at(SIZE_MAX) <= static_cast<double>(options_.max_memory_mb) * (1 << 20)) {
      // Every texture whole within the whole bound: the TextureSystem then reads nothing and needs
      // no cache (five 2048^2 textures, 447 MB, in the default 512).
      cap = SIZE_MAX;
    } else {
      for (size_t texels = size_t(1) << 26; texels > CoarseLevels::kHeldTexels; texels >>= 2) {
        if (total_at(texels) <= held_budget()) {
          cap = texels;
          break;
        }
      }
    }
    if (cap == 0) return;
    std::vector<File*> gaining;
    for (File& f : files_) {
      if (!f.coarse.empty() && LevelBuilder::first_level(f.info.width, f.info.height, cap) < f.coarse.first()) gaining.push_back(&f);
    }
    if (gaining.empty()) return;
    // Each read is a decode on one thread (four 2048^2 PNGs: 0.8 s one after another).
    tbb::parallel_for(size_t(0), gaining.size(), [&](size_t i) {
      File& f = *gaining[i];
      const bool colour = f.info.encoding == TextureEncoding::kColour;
      TextureScan scan = f.bytes ? scan_texture_memory(f.info.path, f.format, *f.bytes, colour, cap)
                                 : scan_texture(f.info.path, colour, cap);
      f.coarse = std::move(scan.levels);
    });
    held_bytes_ = 0;
    for (File& f : files_) add_held(f);
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
    std::string format;                                 // of `bytes`
    CoarseLevels coarse;
  };

  // The levels a new texture may hold: kHeldTexels while the held levels take at most 3/4 of the
  // cache's bound (64 textures of 4096^2 hold 358 MB: so that a render that sees all of them from
  // afar never asks the TextureSystem to make levels from files it cannot read in pieces, such as
  // PNG), then kSmallTexels.
  size_t held_texels() const {
    const double largest = 4.0 * sizeof(float) * CoarseLevels::kHeldTexels * 4 / 3;  // one full set
    return held_bytes_ + largest <= held_budget() ? CoarseLevels::kHeldTexels : CoarseLevels::kSmallTexels;
  }
  double held_budget() const { return 0.75 * options_.max_memory_mb * (1 << 20); }
  // Counts what `f` holds, and takes it off the TextureSystem's bound.
  void add_held(File& f) {
    f.info.held_first = f.coarse.empty() ? -1 : f.coarse.first();
    const CoarseLevels::Level* last = f.coarse.empty() ? nullptr : &f.coarse.levels().back();
    if (last && last->width == 1 && last->height == 1) {
      for (int c = 0; c < 3; ++c) f.info.mean[c] = last->texels[c];
      f.info.mean[3] = last->stride == 4 ? last->texels[3] : 1.0f;  // RGB levels: every alpha is 1
      f.info.has_mean = true;
    }
    for (const CoarseLevels::Level& l : f.coarse.levels()) held_bytes_ += sizeof(float) * l.texels.size();
    ts_->attribute("max_memory_MB", std::max(kMinCacheMb, options_.max_memory_mb - static_cast<float>(held_bytes_ / (1 << 20))));
  }

  // custom: opened through pt's reader (texture_input.cpp) under `cache_name`. What pt holds is
  // taken off the cache's own bound.
  void register_file(File& f, const std::string& path, TextureEncoding encoding, TextureScan& scan,
                     const std::string& cache_name, bool custom) {
    f.info.path = path;
    f.info.encoding = encoding;
    f.info.width = scan.header.width;
    f.info.height = scan.header.height;
    f.info.channels = static_cast<int>(scan.header.channel_count());
    f.info.mip_levels = scan.mip_levels;
    const OIIO::ustring key(cache_name);
    if (custom) ts_->imagecache()->add_file(key, &make_cache_input);
    f.handle = ts_->get_texture_handle(key);
    if (!f.handle) throw Error(path, "the texture system cannot open it: " + ts_->geterror());
    f.coarse = std::move(scan.levels);
    add_held(f);
    files_.push_back(std::move(f));
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
    float s = q.s + q.dsdc, t = q.t + q.dtdc, dsdx = q.dsdx, dtdx = q.dtdx, dsdy = q.dsdy, dtdy = q.dtdy;
    if (options_.filter == TextureFilter::kBilinear) {
      opt.mipmode = OIIO::TextureOpt::MipModeNoMIP;
      s = q.s, t = q.t;
      dsdx = dtdx = dsdy = dtdy = 0.0f;
    } else {
      opt.mipmode = q.isotropic ? OIIO::TextureOpt::MipModeTrilinear : OIIO::TextureOpt::MipModeAniso;
    }
    OIIO::TextureSystem::Perthread* thread = ts_->get_perthread_info();
    if (!ts_->texture(f.handle, thread, opt, s, t, dsdx, dtdx, dsdy, dtdy, channels, out)) {
      ts_->geterror();  // the file was checked at load; a read failing now shows as black
      return false;
    }
    return true;
  }

  static constexpr float kMinCacheMb = 16.0f;
  TextureCacheOptions options_;
  double held_bytes_ = 0;  // in CoarseLevels, taken off the cache's bound
  OIIO::TextureSystem* ts_ = nullptr;
  std::vector<File> files_;  // filled while loading, read only while rendering
  std::mutex mutex_;
};

}  // namespace

std::shared_ptr<TextureCache> make_oiio_texture_cache(const TextureCacheOptions& options) {
  return std::make_shared<OiioTextureCache>(options);
}

}  // namespace pt
