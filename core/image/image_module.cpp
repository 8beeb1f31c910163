// image.h's functions in pt_core: each opens the OpenImageIO module on first use (image_module.h
// says why) and calls its implementation.
#include "core/image/image_module.h"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <vector>

#include "core/image/exr_file.h"
#include "core/util/error.h"
#include "core/util/file_extension.h"
#include "core/util/output_file.h"

namespace pt {
namespace {

constexpr const char* kModuleName = "libpt_image_oiio.so";

std::vector<std::string> candidates() {
  std::vector<std::string> paths;
  if (const char* env = std::getenv("PT_IMAGE_MODULE"); env && *env) paths.emplace_back(env);
  // The module installed with this binary first: a copied or installed pt must not pick up the
  // build tree's module, which changes (or is half-written) whenever the tree is rebuilt.
  std::error_code ec;
  std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    paths.push_back((exe.parent_path() / kModuleName).string());
    paths.push_back((exe.parent_path().parent_path() / "lib" / "pt" / kModuleName).string());
  }
#ifdef PT_IMAGE_MODULE_PATH
  paths.emplace_back(PT_IMAGE_MODULE_PATH);  // the build tree's: the test programs, which sit elsewhere
#endif
  return paths;
}

const ImageModule* load() {
  std::string tried;
  for (const std::string& path : candidates()) {
    if (!std::filesystem::exists(path)) {
      tried += (tried.empty() ? "" : ", ") + path;
      continue;
    }
    void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) throw Error(path, std::string("cannot load the image module: ") + ::dlerror());
    auto entry = reinterpret_cast<const ImageModule* (*)()>(::dlsym(handle, "pt_image_module_table"));
    if (!entry) throw Error(path, "is not pt's image module (no pt_image_module_table)");
    const ImageModule* table = entry();
    if (table->version != ImageModule::kVersion) throw Error(path, "is an image module of another pt version");
    return table;
  }
  throw Error(std::string("cannot find the image module ") + kModuleName + " (looked for " + tried +
              "); install it beside pt, or name it in PT_IMAGE_MODULE");
}

}  // namespace

const ImageModule& image_module() {
  static std::once_flag once;
  static const ImageModule* table = nullptr;
  std::call_once(once, [] { table = load(); });
  return *table;
}

void write_image(const std::string& path, const Image& image, const WriteOptions& options) {
  // Most renders write an .exr, and OpenEXR (linked into pt_core for part files) writes it exactly
  // as OpenImageIO would: loading OpenImageIO for it cost 0.6 CPU-seconds per render.
  if (lower_extension(path) == ".exr") {
    check_output_path(path);
    write_exr(path, image, options.compression);
    return;
  }
  image_module().write_image(path, image, options);
}
Image read_image(const std::string& path) { return image_module().read_image(path); }
Image read_image_header(const std::string& path) { return image_module().read_image_header(path); }
std::shared_ptr<Texture> read_texture(const std::string& path) { return image_module().read_texture(path); }
std::shared_ptr<TextureCache> make_texture_cache(const TextureCacheOptions& options) {
  return image_module().make_texture_cache(options);
}

}  // namespace pt
