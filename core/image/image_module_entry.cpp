// The table libpt_image_oiio.so exports (image_module.h): the OpenImageIO implementations of
// image.h's functions, in image_io.cpp.
#include "core/image/image_module.h"
#include "core/image/texture_module.h"

extern "C" __attribute__((visibility("default"))) const pt::ImageModule* pt_image_module_table() {
  static const pt::ImageModule table = {pt::ImageModule::kVersion, &pt::write_image, &pt::read_image,
                                        &pt::read_image_header, &pt::read_texture,
                                        &pt::make_oiio_texture_cache};
  return &table;
}
