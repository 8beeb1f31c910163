// OpenImageIO is loaded when pt first reads or writes an image, not when pt starts. Debian's
// libOpenImageIO pulls in about 260 shared libraries (OpenCV, FFmpeg, GDAL, GStreamer ...), and
// binding their symbols costs every process about half a CPU-second before main() (callgrind: 91%
// of `pt --version`); a render that writes only a part file (renderer/farm/part_file.h) or a command
// that fails early never needs them. So image_io.cpp is built into a module,
// libpt_image_oiio.so, which pt_core opens on the first call of a function of image.h
// (image_module.cpp forwards them all through this table).
#pragma once
#include <memory>
#include <string>

#include "core/image/image.h"
#include "core/image/texture_cache.h"

namespace pt {

struct ImageModule {
  static constexpr int kVersion = 4;  // bumped when the table changes
  int version;
  void (*write_image)(const std::string&, const Image&, const WriteOptions&);
  Image (*read_image)(const std::string&);
  Image (*read_image_header)(const std::string&);
  std::shared_ptr<Texture> (*read_texture)(const std::string&);
  std::shared_ptr<TextureCache> (*make_texture_cache)(const TextureCacheOptions&);
};

// Where the module is looked for: $PT_IMAGE_MODULE, beside the running executable, in ../lib/pt
// from it, then the build tree's copy (for the test programs). Throws pt::Error when none loads.
const ImageModule& image_module();

}  // namespace pt

// The one symbol the module exports.
extern "C" const pt::ImageModule* pt_image_module_table();
