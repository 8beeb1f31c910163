#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>

#include "core/image/image.h"
#include "core/image/texture_module.h"
#include "core/util/error.h"
#include "core/util/file_extension.h"
#include "core/util/input_file.h"
#include "core/util/output_file.h"

namespace pt {
namespace fs = std::filesystem;

namespace {
// OpenImageIO may queue several messages separated by newlines; errors are printed as one line.
std::string one_line(std::string message) {
  while (!message.empty() && (message.back() == '\n' || message.back() == '\r')) message.pop_back();
  for (size_t at = message.find('\n'); at != std::string::npos; at = message.find('\n', at)) message.replace(at, 1, "; ");
  return message;
}

// libpng, inside OpenImageIO, prints its own "libpng error: ..." on stderr before OpenImageIO
// reports the failure to us; our error line already carries the reason, so while an image is read
// (at load time, before any progress output) stderr is pointed at /dev/null.
// Textures are read on several threads at once (TextureCache::finish_loading): the first reader
// in silences stderr and the last one out restores it; with a saved descriptor per reader, one could
// save the other's /dev/null and restore that for good.
class QuietStderr {
 public:
  QuietStderr() {
    std::lock_guard<std::mutex> lock(state().mutex);
    if (state().depth++ > 0) return;
    std::fflush(stderr);
    state().saved = ::dup(STDERR_FILENO);
    int null = ::open("/dev/null", O_WRONLY);
    if (state().saved >= 0 && null >= 0) ::dup2(null, STDERR_FILENO);
    if (null >= 0) ::close(null);
  }
  ~QuietStderr() {
    std::lock_guard<std::mutex> lock(state().mutex);
    if (--state().depth > 0) return;
    std::fflush(stderr);
    if (state().saved >= 0) {
      ::dup2(state().saved, STDERR_FILENO);
      ::close(state().saved);
      state().saved = -1;
    }
  }
  QuietStderr(const QuietStderr&) = delete;
  QuietStderr& operator=(const QuietStderr&) = delete;

 private:
  struct State {
    std::mutex mutex;
    int depth = 0;
    int saved = -1;
  };
  static State& state() {
    static State s;
    return s;
  }
};
}  // namespace

void write_image(const std::string& path, const Image& image, const WriteOptions& options) {
  // Refuse a path we must not replace before spending any work on it.
  check_output_path(path);
  bool eight_bit = is_8bit_format(path);
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw Error(path, "no image writer for this extension (use .exr or .png)");
  // The image is encoded into memory and written by OutputFile, which checks every write and the
  // close: OpenImageIO's writers do not all report a full disk (PNG said "wrote" over a truncated
  // file, libjpeg exited on its own).
  OIIO::Filesystem::IOVecOutput encoded;
  if (!out->supports("ioproxy") || !out->set_ioproxy(&encoded)) {
    throw Error(path, "this format cannot be written safely (use .exr or .png)");
  }
  // 8-bit files get the colour, and a fourth channel only where it is alpha ("A", stored linear).
  int channels = static_cast<int>(image.channel_count());
  if (eight_bit) channels = channels >= 4 && image.channels[3] == "A" ? 4 : std::min(3, channels);
  OIIO::ImageSpec spec(image.width, image.height, channels, eight_bit ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
  spec.channelnames.assign(image.channels.begin(), image.channels.begin() + channels);
  for (const auto& [key, value] : image.metadata) spec.attribute(key, value);
  if (!eight_bit) spec.attribute("compression", options.compression);
  // UINT channels hold the float buffer's bits; both types are 4 bytes, so the buffer is written
  // as is in the file's per-channel formats.
  bool raw = !eight_bit && std::any_of(image.uint32_bits.begin(), image.uint32_bits.end(), [](bool b) { return b; });
  if (raw) {
    if (lower_extension(path) != ".exr") throw Error(path, "exact (uint) channels need an .exr file");
    for (int c = 0; c < channels; ++c) {
      spec.channelformats.push_back(image.is_uint32(c) ? OIIO::TypeDesc::UINT32 : OIIO::TypeDesc::FLOAT);
    }
  }
  if (!out->open(path, spec)) {
    std::string message = one_line(out->geterror());
    throw Error(path, "cannot write: " + message);
  }
  bool ok;
  if (eight_bit) {
    float scale = std::exp2(options.exposure);
    std::vector<unsigned char> bytes(static_cast<size_t>(image.width) * image.height * channels);
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        for (int c = 0; c < channels; ++c) {
          float v = c == 3 ? image.at(x, y, c) : image.at(x, y, c) * scale;
          if (!std::isfinite(v)) v = 0.0f;
          v = c == 3 ? std::clamp(v, 0.0f, 1.0f) : srgb_encode(v);
          bytes[(static_cast<size_t>(y) * image.width + x) * channels + c] = static_cast<unsigned char>(std::lround(v * 255.0f));
        }
      }
    }
    ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
  } else {
    ok = out->write_image(raw ? OIIO::TypeDesc::UNKNOWN : OIIO::TypeDesc::FLOAT, image.pixels.data());
  }
  ok = out->close() && ok;
  if (!ok) throw Error(path, "cannot write: " + one_line(out->geterror()));
  const std::vector<unsigned char>& bytes = encoded.buffer();
  write_file(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

namespace {
std::unique_ptr<OIIO::ImageInput> open_image(const std::string& path) {
  require_regular_file(path, "an image");
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw Error(path, "cannot read image: " + one_line(OIIO::geterror()));
  return in;
}

// Size, channel names and string metadata, no pixels.
Image header_of(const OIIO::ImageSpec& spec) {
  Image image;
  image.width = spec.width;
  image.height = spec.height;
  image.channels = spec.channelnames;
  image.channels.resize(std::max(0, spec.nchannels));
  for (const auto& attr : spec.extra_attribs) {
    if (attr.type() == OIIO::TypeDesc::STRING) image.metadata[attr.name().string()] = attr.get_string();
  }
  return image;
}
}  // namespace

namespace {
// keep: the pixels are read into the image; else each strip is checked and dropped, so that
// checking a 4096^2 texture costs one strip of memory. decode: integer files' colour channels are
// sRGB-decoded (else read as stored, normalised to [0, 1]). `rows`, when given, sees each strip.
using RowSink = std::function<void(int y, int rows, const float* data)>;
Image read_opened(OIIO::ImageInput* in, const std::string& path, bool keep = true, bool decode = true,
                  const RowSink& rows = {});

std::unique_ptr<OIIO::ImageInput> open_memory(const std::string& name, const std::string& format,
                                              OIIO::Filesystem::IOMemReader& reader) {
  // OpenImageIO picks the reader by the name's extension; the bytes come through a memory proxy.
  OIIO::ImageSpec config;
  OIIO::Filesystem::IOProxy* proxy = &reader;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  auto in = OIIO::ImageInput::open("embedded." + format, &config);
  if (!in) throw Error(name, "cannot read the embedded " + format + " image: " + one_line(OIIO::geterror()));
  return in;
}
}  // namespace

Image read_image(const std::string& path) {
  QuietStderr quiet;
  auto in = open_image(path);
  return read_opened(in.get(), path);
}

namespace {
TextureScan scan_opened(OIIO::ImageInput* in, const std::string& name, bool colour, size_t held_texels) {
  const OIIO::ImageSpec& spec = in->spec();
  TextureScan scan;
  scan.integer = spec.format.basetype == OIIO::TypeDesc::UINT8 || spec.format.basetype == OIIO::TypeDesc::UINT16;
  int levels = 1;
  while (in->seek_subimage(0, levels)) ++levels;
  scan.mip_levels = levels;
  if (!in->seek_subimage(0, 0)) throw Error(name, "cannot read image: " + one_line(in->geterror()));
  std::optional<LevelBuilder> builder;
  if (spec.width > 0 && spec.height > 0 && spec.nchannels > 0) builder.emplace(spec.width, spec.height, spec.nchannels, held_texels);
  const int nc = spec.nchannels, colour_channels = std::min(3, nc);
  scan.header = read_opened(in, name, false, colour, [&](int y, int rows, const float* data) {
    // A colour texture (base colour, emission) is a reflectance or a radiance: never negative.
    // Integer files cannot be; a float file can, and filtering would carry it into the image.
    for (size_t i = 0; colour && !scan.integer && i < static_cast<size_t>(rows) * spec.width; ++i) {
      for (int c = 0; c < colour_channels; ++c) {
        if (data[i * nc + c] < 0.0f) {
          throw Error(name, "holds a negative colour value (" + std::to_string(data[i * nc + c]) + " at pixel (" +
                                std::to_string(i % spec.width) + ", " + std::to_string(y + i / spec.width) +
                                ")); colour textures are never negative");
        }
      }
    }
    builder->add_rows(y, rows, data);
  });
  scan.levels = builder->finish();
  return scan;
}
}  // namespace

TextureScan scan_texture(const std::string& path, bool colour, size_t held_texels) {
  QuietStderr quiet;
  auto in = open_image(path);
  return scan_opened(in.get(), path, colour, held_texels);
}

TextureScan scan_texture_memory(const std::string& name, const std::string& format, const std::vector<unsigned char>& bytes,
                                bool colour, size_t held_texels) {
  QuietStderr quiet;
  OIIO::Filesystem::IOMemReader reader(const_cast<unsigned char*>(bytes.data()), bytes.size());
  auto in = open_memory(name, format, reader);
  return scan_opened(in.get(), name, colour, held_texels);
}

namespace {
Image read_opened(OIIO::ImageInput* in, const std::string& path, bool keep, bool decode, const RowSink& sink) {
  const OIIO::ImageSpec& spec = in->spec();
  // A deep image (samples at several depths per pixel) has no flat pixels to read: said here, not by
  // OpenImageIO's "without an open file" from the read that would follow.
  if (spec.deep) throw Error(path, "is a deep image (several samples per pixel); pt reads flat images only");
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1) {
    throw Error(path, "unsupported image layout");
  }
  // The header's size is checked before anything is allocated for it, and the pixels are read a
  // strip of rows at a time into a buffer that grows with them: a 100-byte file that claims
  // 20000x10000 pixels fails having committed memory only for what it really holds.
  const int64_t pixel_count = static_cast<int64_t>(spec.width) * spec.height;
  if (spec.width > kMaxImageSide || spec.height > kMaxImageSide || pixel_count > kMaxImagePixels ||
      spec.nchannels > kMaxImageChannels) {
    throw Error(path, "is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " pixels with " +
                          std::to_string(spec.nchannels) + " channels; pt reads images of at most " +
                          std::to_string(kMaxImagePixels >> 20) + " Mpixels (" + std::to_string(kMaxImageSide) +
                          " a side) and " + std::to_string(kMaxImageChannels) + " channels");
  }
  Image image = header_of(spec);
  // UINT channels (an EXR's exact counts and double halves) are read as their bits: the file's
  // own formats, which must then all be 4 bytes wide so the float buffer holds them in place.
  bool raw = false;
  for (int c = 0; c < spec.nchannels; ++c) raw = raw || spec.channelformat(c) == OIIO::TypeDesc::UINT32;
  if (raw) {
    image.uint32_bits.resize(spec.nchannels);
    for (int c = 0; c < spec.nchannels; ++c) {
      OIIO::TypeDesc f = spec.channelformat(c);
      if (f != OIIO::TypeDesc::UINT32 && f != OIIO::TypeDesc::FLOAT) {
        throw Error(path, "unsupported mix of channel types (" + std::string(f.c_str()) + " beside uint)");
      }
      image.uint32_bits[c] = f == OIIO::TypeDesc::UINT32;
    }
  }
  const OIIO::TypeDesc format = raw ? OIIO::TypeDesc::UNKNOWN : OIIO::TypeDesc::FLOAT;
  const size_t row_floats = static_cast<size_t>(spec.width) * spec.nchannels;
  try {
    if (keep) image.pixels.reserve(row_floats * spec.height);  // address space only: pages are touched as rows arrive
  } catch (const std::bad_alloc&) {
    throw Error(path, "is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " pixels with " +
                          std::to_string(spec.nchannels) + " channels: more than this machine's memory holds");
  }
  int strip = std::max(1, static_cast<int>((size_t(16) << 20) / (row_floats * sizeof(float))));
  if (spec.tile_width > 0) strip = std::max(1, strip / spec.tile_height) * spec.tile_height;
  const bool integer = spec.format.basetype == OIIO::TypeDesc::UINT8 || spec.format.basetype == OIIO::TypeDesc::UINT16;
  const int colour = std::min(3, spec.nchannels);
  std::vector<float> scratch;
  for (int y = 0; y < spec.height; y += strip) {
    int rows = std::min(strip, spec.height - y);
    float* dst;
    if (keep) {
      image.pixels.resize(row_floats * (y + rows));
      dst = image.pixels.data() + row_floats * y;
    } else {
      scratch.resize(row_floats * rows);
      dst = scratch.data();
    }
    bool ok = spec.tile_width > 0
                  ? in->read_tiles(0, 0, spec.x, spec.x + spec.width, spec.y + y, spec.y + y + rows, spec.z, spec.z + 1, 0,
                                   spec.nchannels, format, dst)
                  : in->read_scanlines(0, 0, spec.y + y, spec.y + y + rows, spec.z, 0, spec.nchannels, format, dst);
    if (!ok) throw Error(path, "cannot read image: " + one_line(in->geterror()));
    const size_t n = row_floats * rows;
    if (integer) {
      // Integers are finite; their colour channels are decoded by table.
      const size_t texels = n / spec.nchannels;
      for (int c = 0; decode && c < colour; ++c) {
        srgb_decode_integers(dst + c, texels * spec.nchannels - c, spec.nchannels, spec.format.basetype == OIIO::TypeDesc::UINT16);
      }
    } else {
      for (size_t i = 0; i < n; ++i) {
        if (!std::isfinite(dst[i]) && !image.is_uint32(i % spec.nchannels)) throw Error(path, "image holds non-finite values");
      }
    }
    if (sink) sink(y, rows, dst);
  }
  return image;
}

std::shared_ptr<Texture> texture_of(const Image& image, const std::string& path) {
  auto tex = std::make_shared<Texture>();
  tex->path = path;
  tex->width = image.width;
  tex->height = image.height;
  tex->texels.resize(static_cast<size_t>(image.width) * image.height);
  size_t nc = image.channel_count();
  for (size_t i = 0; i < tex->texels.size(); ++i) {
    const float* px = &image.pixels[i * nc];
    tex->texels[i] = nc >= 3 ? Spectrum(px[0], px[1], px[2]) : Spectrum(px[0]);
    // An environment map is radiance: never negative (light sampling would draw by |L| and add -L).
    if (min_component(tex->texels[i]) < 0.0f) {
      throw Error(path, "holds a negative value (" + std::to_string(min_component(tex->texels[i])) + " at pixel (" +
                            std::to_string(i % image.width) + ", " + std::to_string(i / image.width) +
                            ")); radiance is never negative");
    }
  }
  return tex;
}
}  // namespace

Image read_image_header(const std::string& path) {
  QuietStderr quiet;
  return header_of(open_image(path)->spec());
}

std::shared_ptr<Texture> read_texture(const std::string& path) { return texture_of(read_image(path), path); }

}  // namespace pt
