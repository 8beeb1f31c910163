#include "core/image/exr_file.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <cstring>
#include <utility>
#include <limits>

#include "core/scene/render_settings.h"
#include "core/util/error.h"
#include "core/util/input_file.h"
#include "core/util/output_file.h"

namespace pt {
namespace {

constexpr size_t kMaxChannels = 64;

// OpenEXR's output into memory, so that the file is written in one checked step.
class MemoryStream : public Imf::OStream {
 public:
  MemoryStream() : Imf::OStream("memory") {}
  void write(const char c[], int n) override {
    if (at_ + n > bytes_.size()) bytes_.resize(at_ + n);
    std::memcpy(bytes_.data() + at_, c, n);
    at_ += n;
  }
  uint64_t tellp() override { return at_; }
  void seekp(uint64_t pos) override { at_ = pos; }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
  size_t at_ = 0;
};

// Size, channels and metadata from a header; checks them against what pt ever writes.
Image header_image(const Imf::Header& header, const std::string& path) {
  const Imath::Box2i& dw = header.dataWindow();
  int64_t width = int64_t(dw.max.x) - dw.min.x + 1, height = int64_t(dw.max.y) - dw.min.y + 1;
  if (width < 1 || height < 1 || width > RenderSettings::kMaxSide || height > RenderSettings::kMaxSide ||
      width * height > RenderSettings::kMaxPixels) {
    throw Error(path, "an EXR of " + std::to_string(width) + "x" + std::to_string(height) +
                          " pixels is larger than any frame pt renders");
  }
  Image image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  for (auto c = header.channels().begin(); c != header.channels().end(); ++c) {
    if (c.channel().xSampling != 1 || c.channel().ySampling != 1) throw Error(path, "subsampled EXR channels are not supported");
    image.channels.push_back(c.name());
    image.uint32_bits.push_back(c.channel().type == Imf::UINT);
  }
  if (image.channels.empty() || image.channels.size() > kMaxChannels) {
    throw Error(path, "an EXR with " + std::to_string(image.channels.size()) + " channels");
  }
  for (auto a = header.begin(); a != header.end(); ++a) {
    if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&a.attribute())) image.metadata[a.name()] = s->value();
  }
  return image;
}

Imf::Compression compression_named(const std::string& name, const std::string& path) {
  static const std::pair<const char*, Imf::Compression> kNames[] = {
      {"none", Imf::NO_COMPRESSION},     {"rle", Imf::RLE_COMPRESSION},   {"zips", Imf::ZIPS_COMPRESSION},
      {"zip", Imf::ZIP_COMPRESSION},     {"piz", Imf::PIZ_COMPRESSION},   {"pxr24", Imf::PXR24_COMPRESSION},
      {"b44", Imf::B44_COMPRESSION},     {"b44a", Imf::B44A_COMPRESSION}, {"dwaa", Imf::DWAA_COMPRESSION},
      {"dwab", Imf::DWAB_COMPRESSION}};
  for (const auto& [n, c] : kNames) {
    if (name == n) return c;
  }
  throw Error(path, "unknown EXR compression '" + name + "'");
}

}  // namespace

void write_exr(const std::string& path, const Image& image, const std::string& compression) {
  const Imf::Compression packing = compression_named(compression, path);
  MemoryStream stream;
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = packing;
    for (const auto& [key, value] : image.metadata) header.insert(key, Imf::StringAttribute(value));
    Imf::FrameBuffer frame;
    const size_t nc = image.channel_count();
    for (size_t c = 0; c < nc; ++c) {
      Imf::PixelType type = image.is_uint32(c) ? Imf::UINT : Imf::FLOAT;
      header.channels().insert(image.channels[c], Imf::Channel(type));
      char* base = reinterpret_cast<char*>(const_cast<float*>(image.pixels.data() + c));
      frame.insert(image.channels[c], Imf::Slice(type, base, nc * sizeof(float), nc * sizeof(float) * image.width));
    }
    Imf::OutputFile file(stream, header);
    file.setFrameBuffer(frame);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw Error(path, std::string("cannot encode the EXR: ") + e.what());
  }
  write_file(path, stream.bytes());
}

Image read_exr_header(const std::string& path) {
  require_regular_file(path, "a part file");
  try {
    Imf::InputFile file(path.c_str());
    return header_image(file.header(), path);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(path, std::string("cannot read the EXR: ") + e.what());
  }
}

Image read_exr(const std::string& path) {
  require_regular_file(path, "a part file");
  try {
    Imf::InputFile file(path.c_str());
    Image image = header_image(file.header(), path);
    const size_t nc = image.channel_count();
    image.pixels.assign(static_cast<size_t>(image.width) * image.height * nc, 0.0f);
    const Imath::Box2i& dw = file.header().dataWindow();
    Imf::FrameBuffer frame;
    const size_t xs = nc * sizeof(float), ys = xs * image.width;
    for (size_t c = 0; c < nc; ++c) {
      // The slice's origin is pixel (0, 0) of the data window's coordinates.
      char* base = reinterpret_cast<char*>(image.pixels.data() + c) - dw.min.x * static_cast<ptrdiff_t>(xs) -
                   dw.min.y * static_cast<ptrdiff_t>(ys);
      frame.insert(image.channels[c], Imf::Slice(image.is_uint32(c) ? Imf::UINT : Imf::FLOAT, base, xs, ys));
    }
    file.setFrameBuffer(frame);
    if (!file.isComplete()) throw Error(path, "is an incomplete EXR (truncated?)");
    file.readPixels(dw.min.y, dw.max.y);
    return image;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(path, std::string("cannot read the EXR: ") + e.what());
  }
}

}  // namespace pt
